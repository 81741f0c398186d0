// The touch model (Pub. I): the executed grasp re-simulated against N candidate object states
// (x, y, yaw[, scale]), returning the readings each candidate predicts, in one batch.
//
// The scene is never rebuilt per candidate. A planar object pose (x, y, yaw) is a rigid motion
// that leaves the table z = 0 where it is, so closing the hand at world pose H on the object at
// pose T_o gives the same joint angles and contact flags as closing it at T_o^-1 H on the object
// in its own frame: the hand moves into the candidate's frame (for a top grasp, its (x, y, yaw)
// does, and the descent along -z is the same in both frames). A scale s is a different mesh:
// the object frame's mesh (xy-box centre on the z axis, lowest point at z = 0) scaled by s about
// the origin, which keeps it standing on the table. Scales are quantised to multiples of
// `scale_step` (default 0.005, i.e. 0.5 %: the re-simulated scale is within 0.25 % of the
// candidate's) and one simulator per quantised scale is built on first use and kept.
//
// The same batch serves Pub. I's fitness (touch/fitness.hpp) and the likelihoods of Pub. VI.
#pragma once

#include <limits>
#include <map>
#include <memory>
#include <mutex>

#include "bayesgrasp/touch/touch_grasp.hpp"

namespace bayesgrasp::touch {

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct TouchModelOptions {
  SimOptions sim;             ///< the simulator's options (the same as the world's)
  double scale_step = 0.005;  ///< quantisation of the candidate scale, > 0
  double scale_min = 0.25;    ///< candidate scales outside [scale_min, scale_max] are an error
  double scale_max = 4.0;
};

/// Throws std::invalid_argument naming the first bad field (the simulator's too).
void validate(const TouchModelOptions& options);

/// Predicted readings of N candidates (row i = candidate i).
struct TouchPredictions {
  int num_candidates = 0;
  RowMatrixXd joints;                                                            ///< N x J
  Eigen::Matrix<uint8_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> contact;  ///< N x L
  Eigen::VectorXd hand_height;                ///< N, world z of the hand where it closed
  std::vector<uint8_t> collision_at_start;    ///< N, the open hand started inside the candidate
  /// Per link, at the *measured* closed configuration placed in each candidate's frame (filled
  /// only by predict(..., measured), for the continuous fitness): for a link that touched, its
  /// distance to the candidate's surface (m, >= 0; +inf beyond the cap); for a link that did not,
  /// whether it penetrates the candidate. NaN distances: links without shapes or that did not touch.
  RowMatrixXd surface_distance;                                                      ///< N x L
  Eigen::Matrix<uint8_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> penetrating;  ///< N x L
  Eigen::VectorXd scales;          ///< N quantised scales
};

class TouchModel {
 public:
  /// `object` in the object frame (see above); throws std::invalid_argument for a bad mesh or
  /// options (naming them).
  TouchModel(const HandModel& hand, const TriMesh& object, const TouchModelOptions& options = {});

  const HandModel& hand() const { return hand_; }
  const TriMesh& object() const { return object_; }
  const TouchModelOptions& options() const { return options_; }

  /// Re-simulates `grasp` against every row of `states`: (N, 3) rows (x, y, yaw) at scale 1 or
  /// (N, 4) rows (x, y, yaw, scale). `threads` as common/parallel.hpp (0 = all cores).
  TouchPredictions predict(const TouchGrasp& grasp, const RowMatrixXd& states, int threads = 1) const;
  /// The same, plus the surface distances of the measured configuration (for the continuous
  /// contact term), looked for up to `surface_cap` (m; farther is +inf).
  TouchPredictions predict(const TouchGrasp& grasp, const RowMatrixXd& states, const TouchReadings& measured,
                           int threads = 1, double surface_cap = std::numeric_limits<double>::infinity()) const;

  /// The simulator of the object at scale s quantised (built on first use; thread-safe).
  std::shared_ptr<const GraspSimulator> simulator(double scale) const;
  /// s rounded to the nearest multiple of scale_step.
  double quantised_scale(double scale) const;
  /// Number of simulators built so far.
  int cached_scales() const;

 private:
  TouchPredictions run(const TouchGrasp& grasp, const RowMatrixXd& states, const TouchReadings* measured,
                       int threads, double surface_cap) const;

  HandModel hand_;
  TriMesh object_;
  TouchModelOptions options_;
  mutable std::mutex mutex_;
  mutable std::map<long, std::shared_ptr<const GraspSimulator>> simulators_;
};

/// Throws std::invalid_argument naming `name` unless states has 3 or 4 finite columns and N >= 1.
void check_states(const RowMatrixXd& states, const char* name = "states");

}  // namespace bayesgrasp::touch

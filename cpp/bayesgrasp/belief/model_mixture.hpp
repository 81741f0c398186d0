// Pub. VI's belief over the training models of a category (thesis §4.3): per model i a
// shape-fit weight w_i and a planar pose p_i = (x, y, yaw) of that model on the table, updated
// from the finger joint angles m of an executed top grasp G (x, y, yaw, world frame).
//
//   Eq. 4.4  p_i(t) = argmax_p  log N(m; mu_i(G - p), var_i(G - p) + s_n^2)  +  log N(p; p_i(t-1), S)
//   Eq. 4.5  w_i(t) = L_i / sum_j L_j,  L_i = N(m; mu_i(G - p_i(t)), var_i(G - p_i(t)) + s_n^2)
//            (as written in the thesis: the previous weights are forgotten); optionally the
//            recursive form w_i(t) ~ w_i(t-1) L_i.
//
// G - p is the grasp relative to the model's pose (relative_planar_pose); mu_i and var_i are model
// i's measurement GP (its joint angles) tabulated over relative grasps (RelativePoseGrid channels
// [mean_c0, mean_c0 + K) and [var_c0, var_c0 + K)); S = diag(prior_std^2). Eq. 4.4 is solved by the
// dogleg trust region of optim/ in coordinates scaled by prior_std, started at p_i(t-1).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "bayesgrasp/belief/pose_grid.hpp"
#include "bayesgrasp/optim/trust_region.hpp"

namespace bayesgrasp::belief {

/// log of the smallest normal double: a likelihood below it underflows to zero (or subnormal), so
/// a measurement whose every likelihood is below it is impossible under every model.
constexpr double kLogMinLikelihood = -708.3964185322641;

/// Where model i's measurement moments sit in its grid.
struct MeasurementChannels {
  int mean_c0 = 1;  ///< first mean channel
  int var_c0 = 1;   ///< first variance channel (variance with the GP's noise)
  int k = 0;        ///< number of joints
};

struct ModelPoseOptions {
  Eigen::Vector3d prior_std = Eigen::Vector3d(0.015, 0.015, 0.2617993877991494);  ///< m, m, rad (15 deg)
  double measurement_noise = 0.0;   ///< s_n (rad): joint-angle noise added to the predictive variance
  optim::TrustRegionOptions trust_region;
  void validate() const;
};

struct ModelPoseUpdate {
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();  ///< p_i(t), yaw wrapped into [-pi, pi)
  double log_likelihood = 0.0;  ///< log L_i at p_i(t)
  double log_prior = 0.0;       ///< log N(p_i(t); p_i(t-1), S) up to its constant
  long long evaluations = 0;
  bool converged = false;
};

/// log N(m; mu(G - p), var(G - p) + s_n^2) for candidate poses p (rows of P, (N, 3)).
Eigen::VectorXd measurement_log_likelihood(const RelativePoseGrid& grid, const MeasurementChannels& ch,
                                           const Eigen::Vector3d& grasp, const Eigen::VectorXd& measurement,
                                           const RowMatrixXd& poses, double measurement_noise);

/// Eq. 4.4 for every model (grids[i], channels shared), threads over models (0 = all cores).
/// Throws std::invalid_argument for a measurement of the wrong length or non-finite values, a
/// prior of the wrong size, or bad options.
std::vector<ModelPoseUpdate> map_model_poses(const std::vector<const RelativePoseGrid*>& grids,
                                             const MeasurementChannels& channels, const Eigen::Vector3d& grasp,
                                             const Eigen::VectorXd& measurement, const RowMatrixXd& prior_poses,
                                             const ModelPoseOptions& options, int threads = 1);

struct ModelWeightUpdate {
  Eigen::VectorXd weights;  ///< normalised, sum 1
  bool underflow = false;   ///< every likelihood was zero: the previous weights were kept
};

/// Eq. 4.5 from log-likelihoods (stable: shifted by their maximum). recursive: w ~ w(t-1) L.
/// Every likelihood underflowing (all below the smallest normal double, e.g. an absurd
/// measurement): the previous weights are kept and underflow is set.
ModelWeightUpdate update_model_weights(const Eigen::VectorXd& log_likelihoods, const Eigen::VectorXd& previous,
                                       bool recursive);

/// One model's particles (rows of planar poses x, y, yaw) after a tactile update, beyond the
/// thesis (the joint particle belief over model and pose): systematic resampling when the effective
/// sample size is below threshold * N, then N(0, diag(jitter_std^2)) jitter with the yaw wrapped
/// into [-pi, pi). The model's total weight, log-sum-exp of log_weights, is kept (each particle gets
/// total - log N). All -inf log-weights (a model without weight) are left as they are. Returns
/// whether it resampled.
bool resample_and_jitter(RowMatrixXd& poses, Eigen::VectorXd& log_weights, const Eigen::Vector3d& jitter_std,
                         double threshold, Rng& rng);

}  // namespace bayesgrasp::belief

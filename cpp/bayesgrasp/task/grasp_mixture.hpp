// Eq. 4.1's objective over hand poses: a weighted mixture of pose densities centred on the task
// grasps of the category's training models, carried into the scene by each model's registration:
//
//   J(A) = sum_{i,k} P(A | T_ik, O_i; theta_ik) psi(q_ik) phi(delta_i)
//
// Component c = (i, k) has its grasp pose T_i theta_ik (scene frame) and its weight
// psi(q_ik) phi(delta_i) (computed by the caller); P is a PoseDensity. Candidates are evaluated in
// batches (N poses against every component, threads over candidates).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "bayesgrasp/geometry/mesh.hpp"
#include "bayesgrasp/task/pose_density.hpp"

namespace bayesgrasp::task {

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
/// N x 6 local pose coordinates: translation (m) and rotation vector (rad), both in the scene frame.
using LocalPoses = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>;

struct MixtureValues {
  Eigen::VectorXd value;   // N: J(A)
  RowMatrixXd per_model;   // N x num_models: each model's share of J(A) (empty unless asked)
  Eigen::VectorXi dominant;  // N: the component contributing most (-1 where J(A) = 0)
};

class GraspMixture {
 public:
  /// grasps[c] (scene frame), weights[c] >= 0, models[c] in [0, num_models). Throws
  /// std::invalid_argument naming the argument for mismatched sizes, negative or non-finite
  /// weights, a model index out of range or a non-finite pose.
  GraspMixture(const std::vector<Iso3>& grasps, const Eigen::VectorXd& weights, const std::vector<int>& models,
               int num_models);

  int size() const { return static_cast<int>(weights_.size()); }
  int num_models() const { return num_models_; }
  const Iso3& grasp(int c) const { return grasps_[c]; }
  double weight(int c) const { return weights_[c]; }
  int model(int c) const { return models_[c]; }

  /// J at N candidate poses; per_model fills MixtureValues::per_model. threads: 0 = all cores.
  MixtureValues evaluate(const std::vector<Iso3>& candidates, const PoseDensity& density, bool per_model = false,
                         int threads = 1) const;

 private:
  double component_terms(const Iso3& A, const PoseDensity& d, double* per_model, int* dominant) const;
  std::vector<Iso3> grasps_;
  std::vector<Mat3> rotations_;
  std::vector<Vec3> translations_;
  Eigen::VectorXd weights_;
  std::vector<int> models_;
  int num_models_ = 0;
};

/// Poses from local coordinates around a reference: A = (exp([r]) R_ref, t_ref + t) for each row
/// (t, r) of X. The optimisers search this 6-D box around a starting grasp.
std::vector<Iso3> poses_from_local(const Iso3& reference, const LocalPoses& X);

/// The rotation angle (rad, in [0, pi]) between two rotations.
double rotation_angle(const Mat3& Ra, const Mat3& Rb);

}  // namespace bayesgrasp::task

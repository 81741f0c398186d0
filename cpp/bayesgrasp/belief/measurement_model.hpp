// GP measurement model of the planners, P(M | A, O): the measurement for particle j under action a
// is predicted by a GP at the grasp pose relative to the particle's object pose
// (relative_planar_pose). Header-only so that bg_belief does not need the GP at link time unless
// these are used.
#pragma once

#include "bayesgrasp/belief/entropy.hpp"
#include "bayesgrasp/belief/relative_pose.hpp"
#include "bayesgrasp/gp/gaussian_process.hpp"

namespace bayesgrasp::belief {

/// Batch log-likelihood of an observed measurement (1, P) after action (1, 3 + extra) at every
/// particle (x, y, yaw): the GP's log predictive density (with noise) at the relative poses.
/// One GP call per batch. The GP must outlive the returned function.
inline BatchLogLikelihood gp_measurement_likelihood(const gp::GaussianProcess& model,
                                                    const Eigen::RowVectorXd& action,
                                                    const Eigen::RowVectorXd& measurement) {
  if (measurement.size() != model.output_dim())
    throw std::invalid_argument("measurement: expected one value per GP output");
  if (!measurement.allFinite()) throw std::invalid_argument("measurement: contains NaN or infinity");
  RowMatrixXd a = action;
  return [&model, a, measurement](const RowMatrixXd& X, Eigen::VectorXd& ll) {
    const Eigen::MatrixXd in = relative_planar_pose(a, X);
    const Eigen::MatrixXd Y = measurement.replicate(X.rows(), 1);
    ll = model.log_predictive_density(in, Y);
  };
}

/// Predictive mean and variance (with noise) of the measurement for every (action, particle)
/// pair: (A*N, P) each, rows a*N + j — the input of expected_posterior_entropy_batch.
/// One GP call for all pairs.
inline void gp_predict_measurements(const gp::GaussianProcess& model, const RowMatrixXd& actions,
                                    const RowMatrixXd& poses, RowMatrixXd& mean, RowMatrixXd& var) {
  const Eigen::MatrixXd in = relative_planar_pose(actions, poses);
  Eigen::MatrixXd m, v;
  model.predict(in, m, v, /*include_noise=*/true);
  mean = m;
  var = v;
}

/// Expected posterior weight entropy (Eq. 3.2) of each of A actions under a GP measurement model.
inline std::vector<EntropyEstimate> gp_expected_posterior_entropy(const gp::GaussianProcess& model,
                                                                  const ParticleBelief& belief,
                                                                  const RowMatrixXd& actions, int n_samples,
                                                                  std::uint64_t seed, int n_threads = 1) {
  RowMatrixXd mean, var;
  gp_predict_measurements(model, actions, belief.particles(), mean, var);
  return expected_posterior_entropy_batch(belief.log_weights(), mean, var, static_cast<int>(actions.rows()),
                                          n_samples, seed, n_threads);
}

}  // namespace bayesgrasp::belief

// GP measurement model of the planners, P(M | A, O): the measurement for particle j under action a
// is predicted by a GP at the grasp pose relative to the particle's object pose
// (relative_planar_pose). Compiled into bg_belief, which links bg_gp (CMakeLists.txt).
#pragma once

#include <cstdint>
#include <vector>

#include "bayesgrasp/belief/entropy.hpp"
#include "bayesgrasp/belief/particles.hpp"
#include "bayesgrasp/belief/relative_pose.hpp"
#include "bayesgrasp/gp/gaussian_process.hpp"

namespace bayesgrasp::belief {

/// Batch log-likelihood of an observed measurement (1, P) after action (1, 3 + extra) at every
/// particle (x, y, yaw): the GP's log predictive density (with noise) at the relative poses.
/// One GP call per batch. The GP must outlive the returned function.
BatchLogLikelihood gp_measurement_likelihood(const gp::GaussianProcess& model, const Eigen::RowVectorXd& action,
                                             const Eigen::RowVectorXd& measurement);

/// Predictive mean and variance (with noise) of the measurement for every (action, particle)
/// pair: (A*N, P) each, rows a*N + j — the input of expected_posterior_entropy_batch.
/// One GP call for all pairs.
void gp_predict_measurements(const gp::GaussianProcess& model, const RowMatrixXd& actions, const RowMatrixXd& poses,
                             RowMatrixXd& mean, RowMatrixXd& var);

/// Bayes update of a planar-pose belief (x, y, yaw) with the GP measurement model: reweights by
/// gp_measurement_likelihood in one batch. action: (3 + extra,) of the GP's input dimension.
/// Returns the all-zero-likelihood recovery flag of ParticleBelief::reweight.
bool gp_update(ParticleBelief& belief, const gp::GaussianProcess& model, const Eigen::RowVectorXd& action,
               const Eigen::RowVectorXd& measurement);

/// Expected posterior weight entropy (Eq. 3.2) of each of A actions (A, input_dim) under a GP
/// measurement model, for particles (N, 3) with log_weights (N,).
std::vector<EntropyEstimate> gp_expected_posterior_entropy(const gp::GaussianProcess& model,
                                                           const RowMatrixXd& particles,
                                                           const Eigen::VectorXd& log_weights,
                                                           const RowMatrixXd& actions, int n_samples,
                                                           std::uint64_t seed, int n_threads = 1);
/// The same for a belief's particles and weights.
std::vector<EntropyEstimate> gp_expected_posterior_entropy(const gp::GaussianProcess& model,
                                                           const ParticleBelief& belief, const RowMatrixXd& actions,
                                                           int n_samples, std::uint64_t seed, int n_threads = 1);

}  // namespace bayesgrasp::belief

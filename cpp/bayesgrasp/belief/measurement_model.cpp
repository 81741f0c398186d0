#include "bayesgrasp/belief/measurement_model.hpp"

#include <stdexcept>
#include <string>

#include "bayesgrasp/belief/relative_pose.hpp"

namespace bayesgrasp::belief {

namespace {
void check_action_columns(Eigen::Index columns, const gp::GaussianProcess& model, const char* name) {
  if (columns < 3) throw std::invalid_argument(std::string(name) + ": expected at least (x, y, yaw)");
  if (columns != model.input_dim())
    throw std::invalid_argument(std::string(name) + ": length must equal the GP's input dimension (" +
                                std::to_string(model.input_dim()) + "), got " + std::to_string(columns));
}
}  // namespace

BatchLogLikelihood gp_measurement_likelihood(const gp::GaussianProcess& model, const Eigen::RowVectorXd& action,
                                             const Eigen::RowVectorXd& measurement) {
  check_action_columns(action.size(), model, "action");
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

void gp_predict_measurements(const gp::GaussianProcess& model, const RowMatrixXd& actions, const RowMatrixXd& poses,
                             RowMatrixXd& mean, RowMatrixXd& var) {
  const Eigen::MatrixXd in = relative_planar_pose(actions, poses);
  Eigen::MatrixXd m, v;
  model.predict(in, m, v, gp::Predictive::Observation);
  mean = m;
  var = v;
}

bool gp_update(ParticleBelief& belief, const gp::GaussianProcess& model, const Eigen::RowVectorXd& action,
               const Eigen::RowVectorXd& measurement) {
  if (belief.dim() != 3) throw std::invalid_argument("belief: a GP update needs a planar pose state (x, y, yaw)");
  return belief.update(gp_measurement_likelihood(model, action, measurement));
}

std::vector<EntropyEstimate> gp_expected_posterior_entropy(const gp::GaussianProcess& model,
                                                           const RowMatrixXd& particles,
                                                           const Eigen::VectorXd& log_weights,
                                                           const RowMatrixXd& actions, int n_samples,
                                                           std::uint64_t seed, int n_threads) {
  check_planar_poses(particles, "particles");
  if (log_weights.size() != particles.rows()) throw std::invalid_argument("log_weights: expected one per particle");
  check_action_columns(actions.cols(), model, "actions");
  RowMatrixXd mean, var;
  gp_predict_measurements(model, actions, particles, mean, var);
  return expected_posterior_entropy_batch(log_weights, mean, var, static_cast<int>(actions.rows()), n_samples, seed,
                                          n_threads);
}

std::vector<EntropyEstimate> gp_expected_posterior_entropy(const gp::GaussianProcess& model,
                                                           const ParticleBelief& belief, const RowMatrixXd& actions,
                                                           int n_samples, std::uint64_t seed, int n_threads) {
  return gp_expected_posterior_entropy(model, belief.particles(), belief.log_weights(), actions, n_samples, seed,
                                       n_threads);
}

}  // namespace bayesgrasp::belief

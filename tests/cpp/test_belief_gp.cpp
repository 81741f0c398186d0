// The GP measurement model of the planners (belief/measurement_model.hpp): likelihoods and
// expected posterior entropy from a GP fitted to a known measurement function of the relative pose.
#include <gtest/gtest.h>

#include <cmath>

#include "bayesgrasp/belief/measurement_model.hpp"
#include "bayesgrasp/gp/exact_gp.hpp"

using namespace bayesgrasp;
using belief::RowMatrixXd;

namespace {
// Measurement = the relative pose itself (x, y, yaw): a fully informative sensor.
gp::ExactGP fitted_identity_gp() {
  belief::Rng rng(0);
  const int n = 200;
  Eigen::MatrixXd X(n, 3), Y(n, 3);
  for (int i = 0; i < n; ++i) {
    X.row(i) << -0.3 + 0.6 * belief::uniform01(rng), -0.3 + 0.6 * belief::uniform01(rng),
        -1.0 + 2.0 * belief::uniform01(rng);
    Y.row(i) = X.row(i);
  }
  gp::GPOptions o;
  o.optimize = false;
  o.lengthscale = Eigen::Vector3d(0.5, 0.5, 1.0);
  o.noise = 1e-4;
  gp::ExactGP model(o);
  model.fit(X, Y);
  return model;
}
}  // namespace

TEST(BeliefGP, LikelihoodIsLogPredictiveDensityAtRelativePoses) {
  const gp::ExactGP model = fitted_identity_gp();
  belief::Rng rng(1);
  const auto space = belief::StateSpace::planar_pose(-0.1, 0.1, -0.1, 0.1);
  belief::ParticleBelief b = belief::ParticleBelief::uniform(space, 300, rng);
  const Eigen::RowVector3d action(0.02, -0.01, 0.3);
  const Eigen::RowVector3d measurement(0.05, 0.0, 0.2);
  const auto ll_fn = belief::gp_measurement_likelihood(model, action, measurement);
  Eigen::VectorXd ll(b.size());
  ll_fn(b.particles(), ll);
  // Independently: Gaussian log density with the GP's predictive mean and variance (+ noise).
  Eigen::MatrixXd mean, var;
  model.predict(belief::relative_planar_pose(action, b.particles()), mean, var, gp::Predictive::Observation);
  for (int i = 0; i < b.size(); ++i) {
    double e = 0.0;
    for (int k = 0; k < 3; ++k)
      e += -0.5 * std::log(2 * M_PI * var(i, k)) - 0.5 * std::pow(measurement[k] - mean(i, k), 2) / var(i, k);
    EXPECT_NEAR(ll[i], e, 1e-6 * std::max(1.0, std::abs(e)));
  }
}

TEST(BeliefGP, UpdateConcentratesOnTruePose) {
  const gp::ExactGP model = fitted_identity_gp();
  belief::Rng rng(2);
  const auto space = belief::StateSpace::planar_pose(-0.1, 0.1, -0.1, 0.1);
  // Prior: Gaussian around a vision estimate, inside the GP's training domain (|rel yaw| < 1).
  belief::ParticleBelief b =
      belief::ParticleBelief::gaussian(space, Eigen::Vector3d(0, 0, 0.2), Eigen::Vector3d(0.05, 0.05, 0.15), 1000, rng);
  const Eigen::Vector3d truth(0.03, -0.04, 0.25);
  const Eigen::RowVector3d action(0.0, 0.0, 0.5);
  const RowMatrixXd T = truth.transpose();
  const Eigen::RowVectorXd m = belief::relative_planar_pose(action, T).row(0);  // noise-free sensor
  // Sensor noise of the likelihood: the GP noise (1e-4 variance, std 0.01) -> posterior within a
  // few centimetres / hundredths of a radian; Metropolis moves refine the few particles there.
  const auto ll = belief::gp_measurement_likelihood(model, action, m);
  EXPECT_FALSE(b.update(ll));
  b.resample(rng);
  b.metropolis(ll, Eigen::Vector3d(0.005, 0.005, 0.01), 20, rng);
  const Eigen::VectorXd mu = b.mean();
  EXPECT_NEAR(mu[0], truth[0], 0.01);
  EXPECT_NEAR(mu[1], truth[1], 0.01);
  EXPECT_NEAR(mu[2], truth[2], 0.02);
}

TEST(BeliefGP, ExpectedEntropyMatchesManualPipeline) {
  const gp::ExactGP model = fitted_identity_gp();
  belief::Rng rng(3);
  const auto space = belief::StateSpace::planar_pose(-0.1, 0.1, -0.1, 0.1);
  const belief::ParticleBelief b = belief::ParticleBelief::uniform(space, 200, rng);
  RowMatrixXd actions(3, 3);
  actions << 0, 0, 0, 0.05, 0.05, 0.3, -0.05, 0.02, -0.4;
  const auto e = belief::gp_expected_posterior_entropy(model, b, actions, 40, 7);
  ASSERT_EQ(e.size(), 3u);
  for (int a = 0; a < 3; ++a) {
    Eigen::MatrixXd mean, var;
    model.predict(belief::relative_planar_pose(actions.row(a), b.particles()), mean, var, gp::Predictive::Observation);
    const auto one = belief::expected_posterior_entropy(b.log_weights(), mean, var, 40, 7);
    EXPECT_NEAR(e[a].mean, one.mean, 1e-9);
    // The identity sensor with std 0.01 is very informative: a large drop from log 200.
    EXPECT_LT(e[a].mean, std::log(200.0) - 1.0);
  }
}

// Pub. VI's per-model pose and weight updates (Eqs. 4.4-4.5) against closed-form answers: a
// measurement linear in the relative grasp with a Gaussian prior has a Gaussian posterior.
#include <gtest/gtest.h>

#include <cmath>

#include "bayesgrasp/belief/model_mixture.hpp"

using namespace bayesgrasp;
using namespace bayesgrasp::belief;

namespace {
// One joint whose mean is 10 * rel_x (rad per m) with variance 0.01 everywhere.
RelativePoseGrid linear_grid(double slope = 10.0, double var = 0.01) {
  const int nx = 13, ny = 13, nyaw = 36;
  RowMatrixXd v(nx * ny * nyaw, 3);
  for (int ix = 0; ix < nx; ++ix)
    for (int iy = 0; iy < ny; ++iy)
      for (int k = 0; k < nyaw; ++k) {
        const double x = -0.06 + 0.12 * ix / (nx - 1);
        const int row = (ix * ny + iy) * nyaw + k;
        v(row, 0) = 0.5;
        v(row, 1) = slope * x;
        v(row, 2) = var;
      }
  return RelativePoseGrid({-0.06, -0.06}, {0.06, 0.06}, nx, ny, nyaw, v, Eigen::Vector3d(0.0, NAN, NAN));
}
const MeasurementChannels kChannels{1, 2, 1};
}  // namespace

TEST(ModelMixture, LogLikelihoodIsTheGaussianDensity) {
  const RelativePoseGrid g = linear_grid();
  RowMatrixXd poses(2, 3);
  poses << 0.01, 0.0, 0.0, 0.0, 0.0, 0.0;
  const Eigen::VectorXd m = (Eigen::VectorXd(1) << -0.1).finished();
  const Eigen::VectorXd ll = measurement_log_likelihood(g, kChannels, Eigen::Vector3d::Zero(), m, poses, 0.0);
  // the grasp at the origin is 1 cm along -x of the first pose: mean -0.1 = m (the grid keeps its
  // values in single precision: 1e-6 relative)
  EXPECT_NEAR(ll[0], -0.5 * (std::log(0.01) + std::log(2 * M_PI)), 1e-6);
  EXPECT_NEAR(ll[1], -0.5 * (0.01 / 0.01 + std::log(0.01) + std::log(2 * M_PI)), 1e-6);
  // measurement noise adds to the variance
  const Eigen::VectorXd ln = measurement_log_likelihood(g, kChannels, Eigen::Vector3d::Zero(), m, poses, 0.1);
  EXPECT_NEAR(ln[1], -0.5 * (0.01 / 0.02 + std::log(0.02) + std::log(2 * M_PI)), 1e-6);
  EXPECT_THROW(measurement_log_likelihood(g, kChannels, Eigen::Vector3d::Zero(), Eigen::VectorXd(2), poses, 0.0),
               std::invalid_argument);
}

TEST(ModelMixture, MapPoseIsTheGaussianPosteriorMode) {
  const RelativePoseGrid g = linear_grid();
  // truth p_x = 1 cm: m = 10 * (0 - 0.01) = -0.1; likelihood of p_x is N(0.01, 0.01^2) (sd 0.1 / 10),
  // the prior N(0, 0.015^2): the posterior mode is 0.01 * 0.015^2 / (0.015^2 + 0.01^2)
  const Eigen::VectorXd m = (Eigen::VectorXd(1) << -0.1).finished();
  RowMatrixXd prior(2, 3);
  prior << 0.0, 0.0, 0.0, 0.0, 0.0, 0.0;
  ModelPoseOptions o;
  o.trust_region.gtol = 1e-10;
  const std::vector<const RelativePoseGrid*> grids = {&g, &g};
  const auto u = map_model_poses(grids, kChannels, Eigen::Vector3d::Zero(), m, prior, o, 0);
  const double mode = 0.01 * 0.015 * 0.015 / (0.015 * 0.015 + 0.0001);
  for (const ModelPoseUpdate& r : u) {
    EXPECT_NEAR(r.pose[0], mode, 2e-5);
    EXPECT_NEAR(r.pose[1], 0.0, 1e-6);
    EXPECT_NEAR(r.pose[2], 0.0, 1e-5);
    EXPECT_NEAR(r.log_prior, -0.5 * std::pow(mode / 0.015, 2), 1e-4);
    EXPECT_GT(r.evaluations, 0);
  }
  // a wrong-length measurement or prior is an error naming it
  EXPECT_THROW(map_model_poses(grids, kChannels, Eigen::Vector3d::Zero(), Eigen::VectorXd::Zero(2), prior, o),
               std::invalid_argument);
  EXPECT_THROW(map_model_poses(grids, kChannels, Eigen::Vector3d::Zero(), m, prior.topRows(1), o), std::invalid_argument);
}

TEST(ModelMixture, WeightsByEq45PlainRecursiveAndUnderflow) {
  const Eigen::Vector3d ll(std::log(1.0), std::log(3.0), -1e300);
  const Eigen::Vector3d prev(0.5, 0.25, 0.25);
  const ModelWeightUpdate plain = update_model_weights(ll, prev, false);
  EXPECT_NEAR(plain.weights[0], 0.25, 1e-12);
  EXPECT_NEAR(plain.weights[1], 0.75, 1e-12);
  EXPECT_EQ(plain.weights[2], 0.0);
  const ModelWeightUpdate rec = update_model_weights(ll, prev, true);  // 0.5 * 1 : 0.25 * 3
  EXPECT_NEAR(rec.weights[0], 0.4, 1e-12);
  EXPECT_NEAR(rec.weights[1], 0.6, 1e-12);
  const double ninf = -std::numeric_limits<double>::infinity();
  const ModelWeightUpdate none = update_model_weights(Eigen::Vector3d(ninf, ninf, ninf), prev, false);
  EXPECT_TRUE(none.underflow);
  EXPECT_NEAR(none.weights[0], 0.5, 1e-15);
  // small likelihoods are fine (the maximum is shifted out) ...
  const ModelWeightUpdate tiny = update_model_weights(Eigen::Vector3d(-700.0, -700.0 + std::log(3.0), -5000.0), prev, false);
  EXPECT_FALSE(tiny.underflow);
  EXPECT_NEAR(tiny.weights[1], 0.75, 1e-12);
  // ... but when every one underflows a double the measurement explains nothing: weights kept
  const ModelWeightUpdate under = update_model_weights(Eigen::Vector3d(-2000.0, -1000.0, -5000.0), prev, false);
  EXPECT_TRUE(under.underflow);
  EXPECT_NEAR(under.weights[1], 0.25, 1e-15);
  EXPECT_THROW(update_model_weights(Eigen::Vector3d(NAN, 0, 0), prev, false), std::invalid_argument);
}

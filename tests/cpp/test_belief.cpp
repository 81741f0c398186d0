// Tests of particle beliefs: resampling unbiasedness, weights and ESS, Metropolis recovering a
// known posterior, angle wrapping, the all-zero-likelihood recovery, entropy estimates and the
// expected posterior entropy of Eq. 3.2, the planar relative pose and its inverse, bad input.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <limits>

#include "bayesgrasp/belief/entropy.hpp"
#include "bayesgrasp/belief/particles.hpp"
#include "bayesgrasp/belief/relative_pose.hpp"

using namespace bayesgrasp::belief;

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
StateSpace box2(double lo, double hi) { return StateSpace(Eigen::Vector2d(lo, lo), Eigen::Vector2d(hi, hi)); }
}  // namespace

// ---------------------------------------------------------------- resampling

class ResamplingUnbiased : public ::testing::TestWithParam<Resampling> {};

TEST_P(ResamplingUnbiased, ExpectedCopiesProportionalToWeights) {
  // Expected copies of particle i: n w_i. Over S independent seeds the mean count has std
  // sqrt(Var/S); Var <= n w_i (1 - w_i) for multinomial, and for systematic/stratified the count
  // is a sum of independent (stratified) or 0/1-per-stratum indicators with Var <= n w_i too.
  // Tolerance 5 standard deviations.
  Eigen::VectorXd w(6);
  w << 0.03, 0.07, 0.1, 0.2, 0.25, 0.35;
  const int n = 10, S = 20000;
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(6);
  for (int s = 0; s < S; ++s) {
    Rng rng(s);
    for (int i : resample_indices(w, n, GetParam(), rng)) mean[i] += 1.0 / S;
  }
  for (int i = 0; i < 6; ++i) {
    const double sd = std::sqrt(n * w[i] * (1.0 - w[i]) / S);
    EXPECT_NEAR(mean[i], n * w[i], 5.0 * sd + 1e-12) << "particle " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Schemes, ResamplingUnbiased,
                         ::testing::Values(Resampling::Systematic, Resampling::Stratified, Resampling::Multinomial));

TEST(BeliefResampling, SystematicCountsAreFloorOrCeil) {
  // A property of systematic resampling: particle i gets floor(n w_i) or ceil(n w_i) copies.
  Eigen::VectorXd w(4);
  w << 0.125, 0.375, 0.3, 0.2;
  for (int s = 0; s < 200; ++s) {
    Rng rng(s);
    std::vector<int> c(4, 0);
    for (int i : resample_indices(w, 20, Resampling::Systematic, rng)) ++c[i];
    for (int i = 0; i < 4; ++i) {
      EXPECT_GE(c[i], std::floor(20 * w[i]) - 1e-9);
      EXPECT_LE(c[i], std::ceil(20 * w[i]) + 1e-9);
    }
  }
}

TEST(BeliefResampling, ResampleMakesWeightsUniform) {
  Rng rng(1);
  RowMatrixXd X(3, 2);
  X << 0, 0, 1, 1, 2, 2;
  ParticleBelief b(box2(-5, 5), X, Eigen::Vector3d(std::log(0.0001), std::log(0.0001), 0.0));
  b.resample(rng);
  EXPECT_NEAR(b.ess(), 3.0, 1e-12);
  // Particle 2 carries ~99.98% of the weight: all copies are of it.
  for (int i = 0; i < 3; ++i) EXPECT_EQ(b.particles()(i, 0), 2.0);
}

TEST(BeliefResampling, ResampleIfNeededUsesEssThreshold) {
  Rng rng(2);
  ParticleBelief b(box2(-1, 1), RowMatrixXd::Zero(4, 2), Eigen::Vector4d(0.0, 0.0, 0.0, std::log(3.0)));
  // w = (1, 1, 1, 3)/6: ESS = 36 / 12 = 3 of 4.
  EXPECT_NEAR(b.ess(), 3.0, 1e-12);
  EXPECT_FALSE(b.resample_if_needed(rng, 0.5));  // 3 >= 2
  EXPECT_TRUE(b.resample_if_needed(rng, 0.9));   // 3 < 3.6
  EXPECT_NEAR(b.ess(), 4.0, 1e-12);
}

TEST(BeliefInit, GaussianAroundEstimateIsTruncatedAndCentred) {
  Rng rng(7);
  const StateSpace s = StateSpace::planar_pose(-0.1, 0.1, -0.1, 0.1);
  const ParticleBelief b = ParticleBelief::gaussian(s, Eigen::Vector3d(0.01, -0.02, 3.0), Eigen::Vector3d(0.01, 0.01, 0.2), 20000, rng);
  const RowMatrixXd& X = b.particles();
  EXPECT_NEAR(X.col(0).mean(), 0.01, 4 * 0.01 / std::sqrt(20000.0));
  EXPECT_NEAR(X.col(1).mean(), -0.02, 4 * 0.01 / std::sqrt(20000.0));
  EXPECT_NEAR(b.mean()[2], 3.0, 0.01);  // circular mean across the +-pi seam
  EXPECT_LT(X.col(2).maxCoeff(), M_PI);
  EXPECT_GE(X.col(2).minCoeff(), -M_PI);
  // Truncation: a mean near the edge puts every particle inside the box.
  const ParticleBelief e = ParticleBelief::gaussian(s, Eigen::Vector3d(0.099, 0, 0), Eigen::Vector3d(0.05, 0.01, 0.1), 2000, rng);
  EXPECT_LE(e.particles().col(0).maxCoeff(), 0.1);
}

// ---------------------------------------------------------------- weights, ESS, entropy

TEST(BeliefWeights, EssAndWeightEntropyByHand) {
  RowMatrixXd X = RowMatrixXd::Zero(3, 2);
  ParticleBelief b(box2(-1, 1), X, Eigen::Vector3d(std::log(0.5), std::log(0.25), std::log(0.25)));
  EXPECT_NEAR(b.ess(), 1.0 / (0.25 + 2 * 0.0625), 1e-12);            // 8/3
  EXPECT_NEAR(weight_entropy(b.log_weights()), 1.5 * std::log(2.0), 1e-12);
  // Uniform weights: ESS N, entropy log N, whatever the (unnormalised) level.
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(1000, -3.7);
  EXPECT_NEAR(weight_entropy(u), std::log(1000.0), 1e-12);
  ParticleBelief ub(box2(-1, 1), RowMatrixXd::Zero(1000, 2), u);
  EXPECT_NEAR(ub.ess(), 1000.0, 1e-9);
  // One particle carries everything (others zero weight): entropy 0, ESS 1.
  Eigen::VectorXd one = Eigen::VectorXd::Constant(5, -kInf);
  one[2] = 0.0;
  EXPECT_NEAR(weight_entropy(one), 0.0, 1e-15);
  EXPECT_NEAR(ParticleBelief(box2(-1, 1), RowMatrixXd::Zero(5, 2), one).ess(), 1.0, 1e-15);
}

TEST(BeliefWeights, AllZeroLikelihoodRecoversUniform) {
  Rng rng(2);
  ParticleBelief b = ParticleBelief::uniform(box2(0, 1), 50, rng);
  b.reweight(Eigen::VectorXd::LinSpaced(50, -3, 3));
  EXPECT_LT(b.ess(), 50.0);
  const bool recovered = b.reweight(Eigen::VectorXd::Constant(50, -kInf));
  EXPECT_TRUE(recovered);
  EXPECT_TRUE(b.log_weights().allFinite());
  EXPECT_NEAR(b.ess(), 50.0, 1e-9);
  // Some zero likelihoods are a normal update, not a recovery.
  Eigen::VectorXd ll = Eigen::VectorXd::Zero(50);
  ll.head(49).setConstant(-kInf);
  EXPECT_FALSE(b.reweight(ll));
  EXPECT_NEAR(b.weights()[49], 1.0, 1e-15);
}

TEST(BeliefWeights, UpdateCallsLikelihoodOnceAndMatchesBayes) {
  RowMatrixXd X(3, 2);
  X << 0, 0, 1, 0, 2, 0;
  ParticleBelief b(box2(-5, 5), X);
  int calls = 0;
  b.update([&](const RowMatrixXd& P, Eigen::VectorXd& ll) {
    ++calls;
    ll = -0.5 * (P.col(0).array() - 1.0).square().matrix();  // N(x; 1, 1) up to a constant
  });
  EXPECT_EQ(calls, 1);
  const double e = std::exp(-0.5);
  EXPECT_NEAR(b.weights()[1], 1.0 / (1.0 + 2.0 * e), 1e-12);
  EXPECT_NEAR(b.weights()[0], e / (1.0 + 2.0 * e), 1e-12);
}

// ---------------------------------------------------------------- Metropolis

TEST(BeliefMetropolis, RecoversKnown2DGaussian) {
  // Target N(mu, C) restricted to [-2, 2]^2 (truncation negligible: > 10 sigma). 4000 particles
  // start uniform, 150 sweeps; particles are independent chains, so the sample mean has standard
  // error sqrt(C_kk / N) ~ 0.0032 (x) and the covariance entries ~ C_kk sqrt(2/N) ~ 0.0009.
  const Eigen::Vector2d mu(0.3, -0.2);
  Eigen::Matrix2d C;
  C << 0.04, 0.012, 0.012, 0.01;
  const Eigen::Matrix2d P = C.inverse();
  auto logp = [&](const RowMatrixXd& X, Eigen::VectorXd& ll) {
    for (Eigen::Index i = 0; i < X.rows(); ++i) {
      const Eigen::Vector2d d = X.row(i).transpose() - mu;
      ll[i] = -0.5 * d.dot(P * d);
    }
  };
  Rng rng(11);
  ParticleBelief b = ParticleBelief::uniform(box2(-2, 2), 4000, rng);
  const MetropolisStats st = b.metropolis(logp, Eigen::Vector2d(0.15, 0.08), 150, rng);
  EXPECT_EQ(st.evaluations, 4000LL * 151);
  EXPECT_GT(st.acceptance_rate, 0.1);
  const Eigen::Vector2d m = b.particles().colwise().mean().transpose();
  const RowMatrixXd D = b.particles().rowwise() - m.transpose();
  const Eigen::Matrix2d S = (D.transpose() * D) / (b.size() - 1.0);
  EXPECT_NEAR(m[0], mu[0], 0.016);
  EXPECT_NEAR(m[1], mu[1], 0.008);
  EXPECT_NEAR(S(0, 0), C(0, 0), 0.005);
  EXPECT_NEAR(S(1, 1), C(1, 1), 0.0015);
  EXPECT_NEAR(S(0, 1), C(0, 1), 0.0025);
}

TEST(BeliefMetropolis, StaysInBoxAndWrapsYaw) {
  // Flat target over a planar-pose box, large steps: x, y must stay inside, yaw in [-pi, pi).
  Rng rng(5);
  ParticleBelief b = ParticleBelief::uniform(StateSpace::planar_pose(-0.1, 0.1, -0.2, 0.2), 500, rng);
  auto flat = [](const RowMatrixXd& X, Eigen::VectorXd& ll) { ll.setZero(); };
  b.metropolis(flat, Eigen::Vector3d(0.5, 0.5, 5.0), 20, rng);
  const RowMatrixXd& X = b.particles();
  EXPECT_GE(X.col(0).minCoeff(), -0.1);
  EXPECT_LE(X.col(0).maxCoeff(), 0.1);
  EXPECT_GE(X.col(1).minCoeff(), -0.2);
  EXPECT_LE(X.col(1).maxCoeff(), 0.2);
  EXPECT_GE(X.col(2).minCoeff(), -M_PI);
  EXPECT_LT(X.col(2).maxCoeff(), M_PI);
}

TEST(BeliefWrapping, YawWrapsAndCircularMean) {
  const StateSpace s = StateSpace::planar_pose(-1, 1, -1, 1);
  EXPECT_NEAR(s.wrap_value(2, 3.5), 3.5 - 2 * M_PI, 1e-12);
  EXPECT_NEAR(s.wrap_value(2, -7.0), -7.0 + 2 * M_PI, 1e-12);
  EXPECT_NEAR(s.wrap_value(2, M_PI), -M_PI, 1e-12);  // [low, high)
  EXPECT_NEAR(s.difference(2, M_PI - 0.1, -M_PI + 0.1), -0.2, 1e-12);
  RowMatrixXd X(2, 3);
  X << 0, 0, M_PI - 0.1, 0, 0, 7.0 - 2 * M_PI + 2 * M_PI;  // second yaw given unwrapped: 7 rad
  ParticleBelief b(s, X);
  EXPECT_NEAR(b.particles()(1, 2), 7.0 - 2 * M_PI, 1e-12);
  // Two particles at +-(pi - 0.1): circular mean pi (= -pi after wrapping), not 0.
  X << 0, 0, M_PI - 0.1, 0, 0, -M_PI + 0.1;
  ParticleBelief c(s, X);
  EXPECT_NEAR(std::abs(c.mean()[2]), M_PI, 1e-9);
}

TEST(BeliefRoughen, JitterScaledToSpreadAndInsideBox) {
  // Gordon et al.: sigma_k = K E_k N^(-1/D). Particles at x in {0, 1} (E = 1), y = 0.5 (E = 0).
  const int n = 4000;
  RowMatrixXd X(n, 2);
  for (int i = 0; i < n; ++i) X.row(i) << (i % 2), 0.5;
  ParticleBelief b(StateSpace(Eigen::Vector2d(-10, -10), Eigen::Vector2d(10, 10)), X);
  Rng rng(3);
  b.roughen(rng, 0.2);
  const double sigma = 0.2 * 1.0 / std::sqrt(static_cast<double>(n));
  const RowMatrixXd D = b.particles() - X;
  const double sd = std::sqrt(D.col(0).squaredNorm() / n);
  EXPECT_NEAR(sd, sigma, 5.0 * sigma / std::sqrt(2.0 * n));
  EXPECT_EQ(D.col(1).cwiseAbs().maxCoeff(), 0.0);  // zero spread: no jitter
}

// ---------------------------------------------------------------- KDE entropy

TEST(BeliefKDE, GaussianSampleNearSmoothedEntropy) {
  // N draws from N(0, C): the KDE is (asymptotically) N(0, C (1 + f^2)), f = N^(-1/6) (Scott, D = 2),
  // with entropy 1/2 log det(2 pi e C (1 + f^2)); resubstitution biases it down by ~1%.
  const int n = 2000;
  Eigen::Matrix2d C;
  C << 1.0, 0.3, 0.3, 0.5;
  const Eigen::Matrix2d L = C.llt().matrixL();
  Rng rng(4);
  std::normal_distribution<double> normal;
  RowMatrixXd X(n, 2);
  for (int i = 0; i < n; ++i) X.row(i) = (L * Eigen::Vector2d(normal(rng), normal(rng))).transpose();
  const double f2 = std::pow(n, -2.0 / 6.0);
  const double expect = 0.5 * std::log((2 * M_PI * M_E * (1 + f2)) * (2 * M_PI * M_E * (1 + f2)) * C.determinant());
  const double h = kde_entropy(X, Eigen::VectorXd::Zero(n), box2(-10, 10));
  // Sampling error of the estimate ~ sqrt(D / 2N) = 0.022, plus the resubstitution bias (the
  // self-term raises p(x_i), so the estimate lies below the smoothed entropy).
  EXPECT_NEAR(h, expect, 0.1);
  EXPECT_LT(h, expect);
  // Shrinking the cloud by 1/2 in both dims lowers the entropy by exactly 2 log 2.
  const double h2 = kde_entropy(0.5 * X, Eigen::VectorXd::Zero(n), box2(-10, 10));
  EXPECT_NEAR(h - h2, 2.0 * std::log(2.0), 1e-9);
}

TEST(BeliefKDE, MatchesDirectFormulaWithWeights) {
  // Independent evaluation of the documented estimator: C = sum w (x - m)(x - m)^T / (1 - sum w^2),
  // H = f^2 C, f = n_eff^(-1/(D+4)) (Scott) or (n_eff (D+2)/4)^(-1/(D+4)) (Silverman),
  // entropy = -sum_i w_i log sum_j w_j N(x_i - x_j; 0, H).
  const int n = 150, d = 3;
  Rng rng(8);
  std::normal_distribution<double> normal;
  RowMatrixXd X(n, d);
  Eigen::VectorXd lw(n);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < d; ++k) X(i, k) = normal(rng) * (k + 1) * 0.1;
    lw[i] = normal(rng);
  }
  const Eigen::VectorXd w = lw.array().exp() / lw.array().exp().sum();
  const Eigen::VectorXd m = X.transpose() * w;
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(d, d);
  for (int i = 0; i < n; ++i) C += w[i] * (X.row(i).transpose() - m) * (X.row(i) - m.transpose());
  C /= (1.0 - w.squaredNorm());
  const double neff = 1.0 / w.squaredNorm();
  const StateSpace space(Eigen::VectorXd::Constant(d, -5), Eigen::VectorXd::Constant(d, 5));
  for (Bandwidth bw : {Bandwidth::Scott, Bandwidth::Silverman}) {
    const double f = bw == Bandwidth::Scott ? std::pow(neff, -1.0 / (d + 4)) : std::pow(neff * (d + 2) / 4.0, -1.0 / (d + 4));
    const Eigen::MatrixXd H = f * f * C, Hi = H.inverse();
    const double norm = 1.0 / std::sqrt(std::pow(2 * M_PI, d) * H.determinant());
    double expect = 0.0;
    for (int i = 0; i < n; ++i) {
      double p = 0.0;
      for (int j = 0; j < n; ++j) {
        const Eigen::VectorXd dx = (X.row(i) - X.row(j)).transpose();
        p += w[j] * norm * std::exp(-0.5 * dx.dot(Hi * dx));
      }
      expect -= w[i] * std::log(p);
    }
    EXPECT_NEAR(kde_entropy(X, lw, space, bw), expect, 1e-9);
  }
}

TEST(BeliefKDE, WrappedYawClusterAcrossPiEqualsClusterAtZero) {
  // A yaw cluster straddling +-pi must give the same entropy as the same cluster shifted to 0
  // (differences are wrapped); without wrapping it would look spread over the whole circle.
  const int n = 300;
  Rng rng(12);
  std::normal_distribution<double> normal;
  const StateSpace s = StateSpace::planar_pose(-1, 1, -1, 1);
  RowMatrixXd at0(n, 3), atpi(n, 3);
  Eigen::VectorXd lw(n);
  for (int i = 0; i < n; ++i) {
    const double x = 0.1 * normal(rng), y = 0.1 * normal(rng), yaw = 0.2 * normal(rng);
    at0.row(i) << x, y, yaw;
    atpi.row(i) << x, y, s.wrap_value(2, yaw + M_PI);
    lw[i] = 0.3 * normal(rng);
  }
  EXPECT_NEAR(kde_entropy(atpi, lw, s), kde_entropy(at0, lw, s), 1e-9);
  const StateSpace nowrap(s.low, s.high);
  EXPECT_GT(kde_entropy(atpi, lw, nowrap), kde_entropy(at0, lw, s) + 1.0);
}

// ---------------------------------------------------------------- expected posterior entropy

TEST(BeliefExpectedEntropy, UninformativeMeasurementGivesNoDrop) {
  // Predicted measurement the same at every particle: the posterior equals the prior for every
  // sampled m, so the expected posterior entropy is the prior's weight entropy exactly.
  const int n = 200;
  Rng rng(6);
  Eigen::VectorXd lw(n);
  for (int i = 0; i < n; ++i) lw[i] = std::log(0.1 + uniform01(rng));
  const RowMatrixXd mean = RowMatrixXd::Constant(n, 2, 0.7), var = RowMatrixXd::Constant(n, 2, 0.05);
  const EntropyEstimate e = expected_posterior_entropy(lw, mean, var, 50, 1);
  EXPECT_NEAR(e.mean, weight_entropy(lw), 1e-12);
  EXPECT_NEAR(e.std_error, 0.0, 1e-12);
}

TEST(BeliefExpectedEntropy, InformativeMeasurementGivesDrop) {
  // Measurement = particle index / N (distinct per particle) with tiny noise: each sampled m
  // identifies its particle, so the posterior is nearly one-hot and the entropy drops to ~0.
  // With noise comparable to the spacing it drops part-way; an uninformative model not at all.
  const int n = 100;
  const Eigen::VectorXd lw = Eigen::VectorXd::Zero(n);
  RowMatrixXd mean(n, 1);
  for (int i = 0; i < n; ++i) mean(i, 0) = static_cast<double>(i) / n;
  const double h0 = std::log(static_cast<double>(n));
  const EntropyEstimate sharp = expected_posterior_entropy(lw, mean, RowMatrixXd::Constant(n, 1, 1e-8), 200, 2);
  const EntropyEstimate blurry = expected_posterior_entropy(lw, mean, RowMatrixXd::Constant(n, 1, 0.01), 200, 2);
  EXPECT_LT(sharp.mean, 0.01);
  EXPECT_LT(blurry.mean, h0 - 0.5);
  EXPECT_GT(blurry.mean, sharp.mean + 1.0);
  // Independent value of the blurry case by quadrature over m instead of sampling:
  // E = int p(m) H(posterior | m) dm, p(m) = (1/N) sum_j N(m; mu_j, s^2), on a fine grid.
  const double s2 = 0.01;
  double expect = 0.0;
  const double lo = -0.6, hi = 1.6, dm = 1e-4;
  for (double m = lo; m <= hi; m += dm) {
    Eigen::VectorXd l(n);
    for (int i = 0; i < n; ++i) l[i] = -0.5 * (m - mean(i, 0)) * (m - mean(i, 0)) / s2;
    const double pm = l.array().exp().sum() / n / std::sqrt(2 * M_PI * s2);
    expect += pm * weight_entropy(l) * dm;
  }
  const EntropyEstimate many = expected_posterior_entropy(lw, mean, RowMatrixXd::Constant(n, 1, s2), 4000, 3);
  EXPECT_NEAR(blurry.mean, expect, 4.0 * blurry.std_error);
  EXPECT_NEAR(many.mean, expect, 4.0 * many.std_error);
  EXPECT_LT(many.std_error, blurry.std_error);
}

TEST(BeliefExpectedEntropy, BatchMatchesSingleAndSeedsRepeat) {
  const int n = 60, A = 4, K = 3;
  Rng rng(9);
  Eigen::VectorXd lw(n);
  for (int i = 0; i < n; ++i) lw[i] = -uniform01(rng);
  RowMatrixXd mean(A * n, K), var(A * n, K);
  for (int r = 0; r < A * n; ++r)
    for (int k = 0; k < K; ++k) { mean(r, k) = uniform01(rng); var(r, k) = 0.01 + 0.1 * uniform01(rng); }
  const auto batch = expected_posterior_entropy_batch(lw, mean, var, A, 30, 42, 2);
  for (int a = 0; a < A; ++a) {
    const EntropyEstimate one = expected_posterior_entropy(lw, mean.middleRows(a * n, n), var.middleRows(a * n, n), 30, 42);
    EXPECT_DOUBLE_EQ(batch[a].mean, one.mean);
    // H(I | M) <= H(I): conditioning on the measurement cannot raise the entropy on average.
    EXPECT_LE(batch[a].mean, weight_entropy(lw) + 1e-12);
  }
  EXPECT_DOUBLE_EQ(expected_posterior_entropy_batch(lw, mean, var, A, 30, 42, 1)[2].mean, batch[2].mean);
  EXPECT_NE(expected_posterior_entropy_batch(lw, mean, var, A, 30, 43, 1)[2].mean, batch[2].mean);
}

// ---------------------------------------------------------------- relative pose

TEST(BeliefRelativePose, ByHand) {
  RowMatrixXd A(2, 4), P(2, 3);
  A << 1, 0, M_PI / 2, 7,   //
      0.5, 0.5, -3.0, 8;
  P << 0, 0, M_PI / 2,      //
      0.5, -0.5, 3.0;
  const RowMatrixXd R = relative_planar_pose(A, P);
  ASSERT_EQ(R.rows(), 4);
  ASSERT_EQ(R.cols(), 4);
  // a0 vs p0: R(-pi/2) (1, 0) = (0, -1), yaw 0.
  EXPECT_NEAR(R(0, 0), 0.0, 1e-12);
  EXPECT_NEAR(R(0, 1), -1.0, 1e-12);
  EXPECT_NEAR(R(0, 2), 0.0, 1e-12);
  EXPECT_EQ(R(0, 3), 7.0);
  // a1 vs p1 (row 1*2 + 1): d = (0, 1), R(-3) d = (sin 3, cos 3); yaw -6 wraps to -6 + 2 pi.
  EXPECT_NEAR(R(3, 0), std::sin(3.0), 1e-12);
  EXPECT_NEAR(R(3, 1), std::cos(3.0), 1e-12);
  EXPECT_NEAR(R(3, 2), -6.0 + 2 * M_PI, 1e-12);
  EXPECT_EQ(R(3, 3), 8.0);
  // Consistency: rotating the relative position back and adding the object position gives the action.
  for (int a = 0; a < 2; ++a)
    for (int j = 0; j < 2; ++j) {
      const double c = std::cos(P(j, 2)), s = std::sin(P(j, 2));
      const double x = R(a * 2 + j, 0), y = R(a * 2 + j, 1);
      EXPECT_NEAR(P(j, 0) + c * x - s * y, A(a, 0), 1e-12);
      EXPECT_NEAR(P(j, 1) + s * x + c * y, A(a, 1), 1e-12);
    }
}

TEST(BeliefComposePose, ByHandWithYawWrapping) {
  // Relative grasp (0.1, 0, 3.0, extra 5) in an object at (1, 2, pi/2): R(pi/2) (0.1, 0) = (0, 0.1),
  // world (1, 2.1); yaw 3.0 + pi/2 = 4.5708 wraps to 4.5708 - 2 pi.
  RowMatrixXd R(1, 4), P(2, 3);
  R << 0.1, 0.0, 3.0, 5.0;
  P << 1.0, 2.0, M_PI / 2,  //
      -1.0, 0.0, -M_PI;
  const RowMatrixXd W = compose_planar_pose(R, P);
  ASSERT_EQ(W.rows(), 2);
  ASSERT_EQ(W.cols(), 4);
  EXPECT_NEAR(W(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(W(0, 1), 2.1, 1e-12);
  EXPECT_NEAR(W(0, 2), 3.0 + M_PI / 2 - 2 * M_PI, 1e-12);
  EXPECT_EQ(W(0, 3), 5.0);
  // Object at (-1, 0, -pi): R(-pi) (0.1, 0) = (-0.1, 0); yaw 3 - pi stays in [-pi, pi).
  EXPECT_NEAR(W(1, 0), -1.1, 1e-12);
  EXPECT_NEAR(W(1, 1), 0.0, 1e-12);
  EXPECT_NEAR(W(1, 2), 3.0 - M_PI, 1e-12);
  // One to one: row i placed by pose i.
  RowMatrixXd R2(2, 3);
  R2 << 0.1, 0.0, 3.0,  //
      0.0, 0.2, -3.0;
  const RowMatrixXd W2 = compose_planar_pose_paired(R2, P);
  ASSERT_EQ(W2.rows(), 2);
  EXPECT_NEAR(W2(0, 1), 2.1, 1e-12);
  EXPECT_NEAR(W2(1, 0), -1.0, 1e-12);  // R(-pi) (0, 0.2) = (0, -0.2)
  EXPECT_NEAR(W2(1, 1), -0.2, 1e-12);
  EXPECT_NEAR(W2(1, 2), -3.0 - M_PI + 2 * M_PI, 1e-12);
  EXPECT_THROW(compose_planar_pose_paired(R2, P.topRows(1)), std::invalid_argument);
}

TEST(BeliefComposePose, InverseOfRelativePoseBothWays) {
  // compose(relative(a, o), o) = a and relative(compose(r, o), o) = r, yaws compared modulo 2 pi,
  // over yaws of several turns.
  Rng rng(5);
  RowMatrixXd A(20, 4), P(7, 3);
  for (int i = 0; i < 20; ++i)
    A.row(i) << uniform01(rng) - 0.5, uniform01(rng) - 0.5, 20.0 * (uniform01(rng) - 0.5), uniform01(rng);
  for (int j = 0; j < 7; ++j) P.row(j) << uniform01(rng) - 0.5, uniform01(rng) - 0.5, 20.0 * (uniform01(rng) - 0.5);
  auto same_angle = [](double a, double b) { return std::abs(std::remainder(a - b, 2 * M_PI)); };
  const RowMatrixXd rel = relative_planar_pose(A, P);  // row a*7 + j
  for (int j = 0; j < 7; ++j) {
    RowMatrixXd rel_j(20, 4);
    for (int a = 0; a < 20; ++a) rel_j.row(a) = rel.row(a * 7 + j);
    const RowMatrixXd back = compose_planar_pose(rel_j, P.row(j));
    const RowMatrixXd back_paired = compose_planar_pose_paired(rel_j, P.row(j).replicate(20, 1));
    for (int a = 0; a < 20; ++a) {
      EXPECT_NEAR(back(a, 0), A(a, 0), 1e-12);
      EXPECT_NEAR(back(a, 1), A(a, 1), 1e-12);
      EXPECT_LT(same_angle(back(a, 2), A(a, 2)), 1e-12);
      EXPECT_GE(back(a, 2), -M_PI);
      EXPECT_LT(back(a, 2), M_PI);
      EXPECT_EQ(back(a, 3), A(a, 3));
      EXPECT_EQ(back_paired.row(a), back.row(a));
    }
  }
  const RowMatrixXd world = compose_planar_pose(A, P);  // A read as relative grasps
  for (int j = 0; j < 7; ++j) {
    RowMatrixXd world_j(20, 4);
    for (int a = 0; a < 20; ++a) world_j.row(a) = world.row(a * 7 + j);
    const RowMatrixXd again = relative_planar_pose(world_j, P.row(j));
    for (int a = 0; a < 20; ++a) {
      EXPECT_NEAR(again(a, 0), A(a, 0), 1e-12);
      EXPECT_NEAR(again(a, 1), A(a, 1), 1e-12);
      EXPECT_LT(same_angle(again(a, 2), A(a, 2)), 1e-12);
    }
  }
}

// ---------------------------------------------------------------- bad input

TEST(BeliefBadInput, Rejected) {
  EXPECT_THROW(StateSpace(Eigen::Vector2d(0, 1), Eigen::Vector2d(1, 0)), std::invalid_argument);  // low > high
  EXPECT_THROW(ParticleBelief(box2(0, 1), RowMatrixXd(0, 2)), std::invalid_argument);             // zero particles
  EXPECT_THROW(ParticleBelief(box2(0, 1), RowMatrixXd::Constant(2, 2, 2.0)), std::invalid_argument);  // outside
  EXPECT_THROW(ParticleBelief(box2(0, 1), RowMatrixXd::Zero(2, 2), Eigen::Vector2d(-kInf, -kInf)),
               std::invalid_argument);  // all-zero weights
  RowMatrixXd X = RowMatrixXd::Zero(2, 2);
  X(0, 0) = std::nan("");
  EXPECT_THROW(ParticleBelief(box2(-1, 1), X), std::invalid_argument);
  ParticleBelief b(box2(-1, 1), RowMatrixXd::Zero(2, 2));
  EXPECT_THROW(b.reweight(Eigen::Vector2d(0.0, std::nan(""))), std::invalid_argument);
  EXPECT_THROW(b.reweight(Eigen::Vector2d(0.0, kInf)), std::invalid_argument);
  EXPECT_THROW(b.reweight(Eigen::Vector3d(0.0, 0.0, 0.0)), std::invalid_argument);
  auto bad = [](const RowMatrixXd& P, Eigen::VectorXd& ll) { ll.setConstant(std::nan("")); };
  Rng rng(0);
  EXPECT_THROW(b.metropolis(bad, Eigen::Vector2d(0.1, 0.1), 1, rng), std::invalid_argument);
  EXPECT_THROW(weight_entropy(Eigen::VectorXd()), std::invalid_argument);
  EXPECT_THROW(expected_posterior_entropy(Eigen::Vector2d(0, 0), RowMatrixXd::Zero(2, 1), RowMatrixXd::Zero(2, 1), 5, 0),
               std::invalid_argument);  // zero variance
  EXPECT_THROW(resampling_from_string("residual"), std::invalid_argument);
}

// Tests of the GP concept: FITC vs exact GP, analytic gradients vs finite differences,
// predictions against closed forms, robustness, seeds.
#include <gtest/gtest.h>

#include <Eigen/LU>

#include <omp.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <tuple>

#include "bayesgrasp/gp/gp.hpp"

using namespace bayesgrasp::gp;

namespace {

void make_data(int N, int D, int P, std::uint64_t seed, Eigen::MatrixXd& X, Eigen::MatrixXd& Y,
               double noise_sd = 0.1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-2.0, 2.0);
  std::normal_distribution<double> nd(0.0, noise_sd);
  X.resize(N, D);
  Y.resize(N, P);
  for (int i = 0; i < N; ++i)
    for (int d = 0; d < D; ++d) X(i, d) = U(rng);
  for (int i = 0; i < N; ++i)
    for (int p = 0; p < P; ++p) {
      double s = 0.0;
      for (int d = 0; d < D; ++d) s += std::sin((1.0 + p + d) * X(i, d));
      Y(i, p) = s + 0.3 * p + nd(rng);
    }
}

// The rows of A twice, one copy after the other (duplicated training inputs).
Eigen::MatrixXd twice(const Eigen::MatrixXd& A) {
  Eigen::MatrixXd out(2 * A.rows(), A.cols());
  out << A, A;
  return out;
}

GPOptions fixed_options(KernelType t = KernelType::SquaredExponential) {
  GPOptions o;
  o.kernel = t;
  o.optimize = false;
  o.normalize_x = false;
  o.normalize_y = false;
  o.lengthscale = Eigen::VectorXd::Constant(1, 0.8);
  o.variance = 1.3;
  o.noise = 0.05;
  return o;
}

// N inputs (and outputs) and every one of them twice (Xd, Yd), with fixed_options() at zero
// noise: the exact covariance is singular without jitter.
struct DuplicatedNoiseFree {
  Eigen::MatrixXd X, Y, Xd, Yd;
  GPOptions options;
};

DuplicatedNoiseFree duplicated_noise_free(int N, int D, std::uint64_t seed) {
  DuplicatedNoiseFree d;
  make_data(N, D, 1, seed, d.X, d.Y);
  d.Xd = twice(d.X);
  d.Yd = twice(d.Y);
  d.options = fixed_options();
  d.options.noise = 0.0;
  return d;
}

}  // namespace

TEST(GPKernel, SquaredExponentialAndMaternClosedForms) {
  Eigen::MatrixXd A(1, 2), B(1, 2);
  A << 0.0, 0.0;
  B << 1.0, 2.0;
  Eigen::VectorXd ls(2);
  ls << 0.5, 2.0;
  const Kernel se(KernelType::SquaredExponential, ls, 2.0);
  const double r2 = 4.0 + 1.0;
  EXPECT_NEAR(se(A, B)(0, 0), 2.0 * std::exp(-0.5 * r2), 1e-14);
  const Kernel m52(KernelType::Matern52, ls, 2.0);
  const double s = std::sqrt(5.0 * r2);
  EXPECT_NEAR(m52(A, B)(0, 0), 2.0 * (1 + s + s * s / 3) * std::exp(-s), 1e-14);
  EXPECT_NEAR(se(A)(0, 0), 2.0, 1e-15);
  EXPECT_THROW(Kernel(KernelType::SquaredExponential, Eigen::VectorXd::Constant(2, -1.0), 1.0),
               std::invalid_argument);
}

namespace {
// Central finite differences of the objective against its analytic gradient.
// Central finite differences of f(theta, grad) -> value against its analytic gradient.
template <class F>
void check_gradient_of(const F& f, const Eigen::VectorXd& theta, double rtol) {
  Eigen::VectorXd g;
  const double f0 = f(theta, g);
  ASSERT_TRUE(std::isfinite(f0));
  ASSERT_EQ(g.size(), theta.size());
  for (Eigen::Index i = 0; i < theta.size(); ++i) {
    const double h = 1e-5 * std::max(1.0, std::abs(theta[i]));
    Eigen::VectorXd tp = theta, tm = theta, gd;
    tp[i] += h;
    tm[i] -= h;
    const double fd = (f(tp, gd) - f(tm, gd)) / (2 * h);
    EXPECT_NEAR(g[i], fd, rtol * std::max(1.0, std::abs(fd))) << "parameter " << i;
  }
}

void check_gradient(const GaussianProcess& gp, const Eigen::VectorXd& theta, double rtol) {
  check_gradient_of([&](const Eigen::VectorXd& t, Eigen::VectorXd& g) { return gp.objective(t, g); }, theta, rtol);
}
}  // namespace

TEST(GPFitc, EqualsExactGPWhenInducingInputsAreTrainingInputs) {
  Eigen::MatrixXd X, Y;
  make_data(40, 2, 2, 1, X, Y);
  for (KernelType t : {KernelType::SquaredExponential, KernelType::Matern52}) {
    GPOptions o = fixed_options(t);
    o.jitter = 1e-10;
    ExactGP exact(o);
    exact.fit(X, Y);
    o.inducing = X;
    SparseGP fitc(o);
    fitc.fit(X, Y);
    EXPECT_NEAR(fitc.log_marginal_likelihood(), exact.log_marginal_likelihood(), 1e-6);
    Eigen::MatrixXd Xs, Ys;
    make_data(25, 2, 2, 2, Xs, Ys);
    Eigen::MatrixXd me, ve, ms, vs;
    exact.predict(Xs, me, ve);
    fitc.predict(Xs, ms, vs);
    EXPECT_LT((me - ms).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_LT((ve - vs).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_LT((exact.log_predictive_density(Xs, Ys) - fitc.log_predictive_density(Xs, Ys)).cwiseAbs().maxCoeff(),
              1e-5);
    // Analytic gradients agree too (same model, same hyper-parameters).
    Eigen::VectorXd ge, gs;
    const Eigen::VectorXd th = exact.parameters();
    exact.objective(th, ge);
    fitc.objective(th, gs);
    EXPECT_LT((ge - gs).cwiseAbs().maxCoeff(), 1e-4);
  }
}

TEST(GPExact, MatchesDirectLinearAlgebra) {
  Eigen::MatrixXd X, Y;
  make_data(30, 3, 1, 3, X, Y);
  GPOptions o = fixed_options();
  ExactGP gp(o);
  gp.fit(X, Y);
  const Kernel k(KernelType::SquaredExponential, Eigen::VectorXd::Constant(3, 0.8), 1.3);
  Eigen::MatrixXd K = k(X);
  K.diagonal().array() += 0.05;
  const Eigen::MatrixXd Kinv = K.inverse();
  Eigen::MatrixXd Xs, Ys;
  make_data(7, 3, 1, 4, Xs, Ys);
  const Eigen::MatrixXd Ks = k(Xs, X);
  const Eigen::VectorXd mean = Ks * Kinv * Y;
  const Eigen::VectorXd var = (k(Xs).diagonal() - (Ks * Kinv * Ks.transpose()).diagonal());
  Eigen::MatrixXd m, v;
  gp.predict(Xs, m, v);
  EXPECT_LT((m.col(0) - mean).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((v.col(0) - var).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((gp.predict_mean(Xs) - m).cwiseAbs().maxCoeff(), 1e-12);
  const double lml = -0.5 * (Y.transpose() * Kinv * Y)(0, 0) - 0.5 * std::log(K.determinant()) -
                     0.5 * 30 * std::log(2 * M_PI);
  EXPECT_NEAR(gp.log_marginal_likelihood(), lml, 1e-8);
  // log predictive density: Gaussian with variance var + noise
  const Eigen::VectorXd lp = gp.log_predictive_density(Xs, Ys);
  for (int i = 0; i < 7; ++i) {
    const double s2 = var[i] + 0.05;
    EXPECT_NEAR(lp[i], -0.5 * std::log(2 * M_PI * s2) - 0.5 * std::pow(Ys(i, 0) - mean[i], 2) / s2, 1e-9);
  }
  // full covariance diagonal equals the variance
  EXPECT_LT((gp.predict_cov(Xs).diagonal() - var).cwiseAbs().maxCoeff(), 1e-9);
}

// Analytic gradients against central differences for every model and kernel, constant mean: the
// exact GP, and FITC with its inducing inputs among the parameters.
class GPGradientFD : public ::testing::TestWithParam<std::tuple<bool, KernelType>> {};

TEST_P(GPGradientFD, MatchesFiniteDifferences) {
  const auto [sparse, kernel] = GetParam();
  const int D = sparse ? 3 : 2;
  Eigen::MatrixXd X, Y;
  make_data(sparse ? 80 : 35, D, 2, sparse ? 6 : 5, X, Y);
  GPOptions o = fixed_options(kernel);
  o.mean = MeanType::Constant;
  o.lengthscale = Eigen::Vector3d(0.7, 1.4, 1.0).head(D);
  std::unique_ptr<GaussianProcess> gp;
  if (sparse) {
    o.n_inducing = 12;
    o.optimize_inducing = true;
    o.normalize_x = true;
    gp = std::make_unique<SparseGP>(o);
  } else {
    gp = std::make_unique<ExactGP>(o);
  }
  gp->fit(X, Y);
  if (sparse) ASSERT_EQ(gp->parameters().size(), 3 + 2 + 2 + 12 * 3);
  check_gradient(*gp, gp->parameters(), 1e-5);
}

INSTANTIATE_TEST_SUITE_P(ModelsAndKernels, GPGradientFD,
                         ::testing::Combine(::testing::Bool(),
                                            ::testing::Values(KernelType::SquaredExponential, KernelType::Matern52)));

TEST(GPGradient, FitcMatchesFiniteDifferencesFixedInducingFarFromTheOrigin) {
  // Fixed inducing inputs take the lengthscale-only gradient contraction (expanded around the
  // inputs' centre); inputs offset by 50 lengthscales, no normalisation, one and three outputs.
  for (const int P : {1, 3}) {
    Eigen::MatrixXd X, Y;
    make_data(90, 3, P, 8 + P, X, Y);
    X.array() += 50.0;
    GPOptions o = fixed_options();
    o.mean = MeanType::Constant;
    o.lengthscale = Eigen::Vector3d(0.7, 1.4, 1.0);
    o.n_inducing = 15;
    SparseGP gp(o);
    gp.fit(X, Y);
    ASSERT_EQ(gp.parameters().size(), 3 + 2 + P);
    check_gradient(gp, gp.parameters(), 1e-5);
  }
}

TEST(GPGradient, ProfiledScaleObjectiveMatchesFiniteDifferencesAndTheFullObjective) {
  // theta_p = [log lengthscales, log(noise / variance), mean]; the profiled objective equals
  // the full objective at the returned scale and is its minimum over the scale.
  for (const int P : {1, 3}) {
    Eigen::MatrixXd X, Y;
    make_data(90, 3, P, 21 + P, X, Y);
    GPOptions o = fixed_options();
    o.mean = P == 1 ? MeanType::Constant : MeanType::Zero;
    o.n_inducing = 15;
    SparseGP gp(o);
    gp.fit(X, Y);
    ASSERT_TRUE(gp.supports_profile());
    const int nc = P == 1 ? 1 : 0;
    Eigen::VectorXd tp(3 + 1 + nc);
    tp << std::log(0.7), std::log(1.3), std::log(1.0), std::log(0.04);
    if (nc) tp[4] = 0.2;
    SCOPED_TRACE("P=" + std::to_string(P));
    check_gradient_of(
        [&](const Eigen::VectorXd& t, Eigen::VectorXd& g) { return gp.profiled_objective(t, g, nullptr); }, tp,
        1e-5);
    Eigen::VectorXd g;
    double ls = 0.0;
    const double f0 = gp.profiled_objective(tp, g, &ls);
    Eigen::VectorXd th(3 + 2 + nc), gf;
    th << tp.head(3), ls, tp[3] + ls, tp.tail(nc);
    EXPECT_NEAR(gp.objective(th, gf), f0, 1e-9 * std::abs(f0));
    for (const double dls : {-0.3, 0.3}) {  // any other scale is worse
      Eigen::VectorXd t2 = th;
      t2[3] += dls;
      t2[4] += dls;
      EXPECT_GT(gp.objective(t2, gf), f0);
    }
  }
}

TEST(GPFit, ProfiledScaleFitReachesTheSameOptimum) {
  Eigen::MatrixXd X, Y;
  make_data(150, 2, 1, 33, X, Y);
  GPOptions o;
  o.n_inducing = 20;
  o.lengthscale = Eigen::VectorXd::Constant(1, 1.0);
  o.variance = 1.0;
  o.noise = 1.0;
  SparseGP full_gp([&] { GPOptions a = o; a.profile_scale = false; return a; }());
  SparseGP prof_gp(o);
  full_gp.fit(X, Y);
  prof_gp.fit(X, Y);
  EXPECT_NEAR(prof_gp.log_marginal_likelihood(), full_gp.log_marginal_likelihood(),
              1e-5 * std::abs(full_gp.log_marginal_likelihood()));
  EXPECT_NEAR(prof_gp.kernel().variance(), full_gp.kernel().variance(), 1e-2 * full_gp.kernel().variance());
}

TEST(GPFit, OptimisationIncreasesLikelihoodAndRecoversNoise) {
  Eigen::MatrixXd X, Y;
  make_data(300, 2, 1, 7, X, Y, 0.1);
  GPOptions o;
  o.n_inducing = 40;
  o.noise = 0.5;
  SparseGP fixed([&] { GPOptions f = o; f.optimize = false; return f; }());
  fixed.fit(X, Y);
  SparseGP gp(o);
  gp.fit(X, Y);
  EXPECT_GT(gp.log_marginal_likelihood(), fixed.log_marginal_likelihood() + 10.0);
  // noise sd 0.1 in raw units: noise variance in standardised units times y_scale^2
  const double noise_raw = gp.noise() * gp.y_scale()[0] * gp.y_scale()[0];
  EXPECT_NEAR(std::sqrt(noise_raw), 0.1, 0.03);
  EXPECT_GT(gp.fit_info().evaluations, 1);
  ExactGP ex(o);
  ex.fit(X, Y);
  EXPECT_NEAR(std::sqrt(ex.noise()) * ex.y_scale()[0], 0.1, 0.03);
  // the exact fit is at least as good as FITC's on the same data
  EXPECT_GE(ex.log_marginal_likelihood(), gp.log_marginal_likelihood() - 1.0);
}

TEST(GPSeeds, SameSeedSameResult) {
  Eigen::MatrixXd X, Y;
  make_data(200, 2, 1, 8, X, Y);
  GPOptions o;
  o.n_inducing = 20;
  o.seed = 42;
  SparseGP a(o), b(o);
  a.fit(X, Y);
  b.fit(X, Y);
  EXPECT_EQ(a.inducing_inputs(), b.inducing_inputs());
  EXPECT_EQ(a.log_marginal_likelihood(), b.log_marginal_likelihood());
  std::mt19937_64 r1(3), r2(3);
  const auto s1 = a.sample(X.topRows(10), 4, r1), s2 = b.sample(X.topRows(10), 4, r2);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(s1[k], s2[k]);
  o.seed = 43;
  SparseGP c(o);
  c.fit(X, Y);
  EXPECT_NE(a.inducing_inputs(), c.inducing_inputs());
}

TEST(GPSample, MarginalAndJointMomentsMatchPrediction) {
  Eigen::MatrixXd X, Y;
  make_data(60, 1, 1, 9, X, Y);
  ExactGP gp(fixed_options());
  gp.fit(X, Y);
  Eigen::MatrixXd Xs(3, 1);
  Xs << -1.0, 0.3, 5.0;
  Eigen::MatrixXd m, v;
  gp.predict(Xs, m, v, Predictive::Observation);
  std::mt19937_64 rng(1);
  const int S = 20000;
  for (bool joint : {false, true}) {
    const auto s = joint ? gp.sample_joint(Xs, S, rng) : gp.sample(Xs, S, rng);
    for (int i = 0; i < 3; ++i) {
      double mu = 0, m2 = 0;
      for (int k = 0; k < S; ++k) mu += s[k](i, 0);
      mu /= S;
      for (int k = 0; k < S; ++k) m2 += std::pow(s[k](i, 0) - mu, 2);
      m2 /= S;
      EXPECT_NEAR(mu, m(i, 0), 5 * std::sqrt(v(i, 0) / S));
      EXPECT_NEAR(m2, v(i, 0), 0.05 * v(i, 0));
    }
  }
}

TEST(GPMultiOutput, SharedHyperparametersEqualSeparateFitsAndIndependentModelsWork) {
  Eigen::MatrixXd X, Y;
  make_data(50, 2, 3, 10, X, Y);
  GPOptions o = fixed_options();
  o.n_inducing = 15;
  SparseGP all(o);
  all.fit(X, Y);
  Eigen::MatrixXd Xs, Ys;
  make_data(9, 2, 3, 11, Xs, Ys);
  const Eigen::MatrixXd m = all.predict_mean(Xs);
  double lml = 0;
  Eigen::VectorXd lp = Eigen::VectorXd::Zero(9);
  for (int p = 0; p < 3; ++p) {
    GPOptions op = o;
    op.inducing = all.inducing_inputs();
    SparseGP one(op);
    one.fit(X, Y.col(p));
    EXPECT_LT((one.predict_mean(Xs).col(0) - m.col(p)).cwiseAbs().maxCoeff(), 1e-9);
    lml += one.log_marginal_likelihood();
    lp += one.log_predictive_density(Xs, Ys.col(p));
  }
  EXPECT_NEAR(all.log_marginal_likelihood(), lml, 1e-8);
  EXPECT_LT((all.log_predictive_density(Xs, Ys) - lp).cwiseAbs().maxCoeff(), 1e-9);
  GPOptions oi;
  oi.max_iter = 30;
  IndependentOutputsGP ind(oi, [oi] { return std::make_unique<ExactGP>(oi); });
  ind.fit(X, Y);
  ASSERT_EQ(ind.n_models(), 3);
  const Eigen::MatrixXd mi = ind.predict_mean(Xs);
  for (int p = 0; p < 3; ++p)
    EXPECT_LT((mi.col(p) - ind.model(p).predict_mean(Xs).col(0)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NE(ind.model(0).kernel().log_lengthscale, ind.model(2).kernel().log_lengthscale);
}

TEST(GPRobustness, DuplicatesZeroNoiseAndExtremeScales) {
  const auto [X, Y, Xd, Yd, o] = duplicated_noise_free(30, 2, 12);
  ExactGP ex(o);
  ex.fit(Xd, Yd);  // singular without jitter
  EXPECT_GT(ex.fit_info().jitter_used, 0.0);
  EXPECT_TRUE(ex.predict_mean(X).allFinite());
  EXPECT_LT((ex.predict_mean(X) - Y).cwiseAbs().maxCoeff(), 1e-3);  // interpolates
  EXPECT_TRUE(std::isfinite(ex.log_marginal_likelihood()));
  SparseGP sp(o);
  sp.fit(Xd, Yd);
  EXPECT_LE(sp.n_inducing(), 30);  // k-means++ finds only the distinct inputs
  EXPECT_TRUE(sp.predict_mean(X).allFinite());
  EXPECT_TRUE(sp.log_predictive_density(X, Y).allFinite());
  // Tiny and huge scales: with normalisation the fit is scale-equivariant.
  GPOptions on;
  on.n_inducing = 20;
  SparseGP base(on), tiny(on), huge(on);
  base.fit(X, Y);
  tiny.fit(X * 1e-6, Y * 1e-8);
  huge.fit(X * 1e6 + Eigen::MatrixXd::Constant(30, 2, 1e9), Y * 1e8);
  const Eigen::MatrixXd mb = base.predict_mean(X);
  EXPECT_LT((tiny.predict_mean(X * 1e-6) * 1e8 - mb).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_LT((huge.predict_mean(X * 1e6 + Eigen::MatrixXd::Constant(30, 2, 1e9)) * 1e-8 - mb).cwiseAbs().maxCoeff(),
            1e-4);
  // Constant outputs: no NaN.
  SparseGP flat(on);
  flat.fit(X, Eigen::MatrixXd::Constant(30, 1, 2.5));
  EXPECT_LT((flat.predict_mean(X).array() - 2.5).abs().maxCoeff(), 1e-6);
}

TEST(GPThreads, ZeroMeansAllCoresAndGivesTheOneThreadResult) {
  // threads = 0: every hardware thread (omp_get_num_procs) for batches of >= 2048 inputs; the
  // predictions are the one-thread predictions bit for bit (each input is computed alone).
  Eigen::MatrixXd X, Y, Xs, Ys;
  make_data(200, 3, 2, 61, X, Y);
  make_data(5000, 3, 1, 62, Xs, Ys);
  for (const bool sparse : {false, true}) {
    GPOptions o = fixed_options();
    o.n_inducing = 30;
    o.threads = 0;
    std::unique_ptr<GaussianProcess> all = sparse ? std::unique_ptr<GaussianProcess>(new SparseGP(o))
                                                  : std::unique_ptr<GaussianProcess>(new ExactGP(o));
    o.threads = 1;
    std::unique_ptr<GaussianProcess> one = sparse ? std::unique_ptr<GaussianProcess>(new SparseGP(o))
                                                  : std::unique_ptr<GaussianProcess>(new ExactGP(o));
    all->fit(X, Y);
    one->fit(X, Y);
    EXPECT_EQ(all->threads(), omp_get_num_procs());
    EXPECT_EQ(one->threads(), 1);
    Eigen::MatrixXd ma, va, m1, v1;
    all->predict(Xs, ma, va);
    one->predict(Xs, m1, v1);
    EXPECT_EQ(ma, m1);
    EXPECT_EQ(va, v1);
    EXPECT_EQ(all->predict_mean(Xs), one->predict_mean(Xs));
    one->set_threads(0);
    EXPECT_EQ(one->threads(), omp_get_num_procs());
    EXPECT_THROW(one->set_threads(-1), std::invalid_argument);
  }
  GPOptions bad;
  bad.threads = -2;
  EXPECT_THROW(ExactGP{bad}, std::invalid_argument);
}

TEST(GPErrors, BadInputIsRejected) {
  Eigen::MatrixXd X, Y;
  make_data(20, 2, 1, 13, X, Y);
  GPOptions o;
  o.lengthscale = Eigen::VectorXd::Constant(1, -1.0);
  EXPECT_THROW(ExactGP{o}, std::invalid_argument);
  o = GPOptions{};
  o.noise = -1;
  EXPECT_THROW(SparseGP{o}, std::invalid_argument);
  ExactGP gp{GPOptions{}};
  EXPECT_THROW(gp.predict_mean(X), std::logic_error);
  EXPECT_THROW(gp.fit(X, Y.topRows(10)), std::invalid_argument);
  Eigen::MatrixXd Xn = X;
  Xn(3, 1) = NAN;
  EXPECT_THROW(gp.fit(Xn, Y), std::invalid_argument);
  gp.fit(X, Y);
  EXPECT_THROW(gp.predict_mean(Eigen::MatrixXd::Zero(3, 3)), std::invalid_argument);
  EXPECT_THROW(gp.log_predictive_density(X, Eigen::MatrixXd::Zero(20, 2)), std::invalid_argument);
}

namespace {
// The same fitted model predicting through the blockwise Eigen path (no packed factor).
struct BlockwiseSparseGP : SparseGP {
  explicit BlockwiseSparseGP(const SparseGP& g) : SparseGP(g) { cache_.G_packed.clear(); }
};
}  // namespace

TEST(GPFitc, FusedPredictionEqualsDenseFormulaAndBlockwisePath) {
  // FITC predictive distribution from its textbook form (Snelson & Ghahramani 2006):
  //   Lambda = diag(Knn - Qnn) + noise,  Sigma = (Kmm + Kmn Lambda^-1 Knm)^-1,
  //   mean = Ksm Sigma Kmn Lambda^-1 y,  var = kss - Ksm (Kmm^-1 - Sigma) Kms.
  // Shapes chosen to hit the kernel's edge cases: M not a multiple of the register tile,
  // batches of 1, 23, 24, 25, 301 inputs (not multiples of the input group), D = 3 and D = 17
  // (the scalar distance fallback), both kernels, two outputs.
  for (const int D : {3, 17})
    for (KernelType t : {KernelType::SquaredExponential, KernelType::Matern52}) {
      Eigen::MatrixXd X, Y, Z, Zy;
      make_data(120, D, 2, 31 + D, X, Y);
      make_data(37, D, 1, 41 + D, Z, Zy);
      GPOptions o = fixed_options(t);
      o.lengthscale = Eigen::VectorXd::Constant(1, D == 3 ? 0.8 : 3.0);
      o.inducing = Z;
      SparseGP gp(o);
      gp.fit(X, Y);
      // Reference in long double (explicit inverses of an ill-conditioned Kmm lose ~8 digits in
      // double), with the jitter the fit used.
      using MatL = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
      const Kernel k(t, Eigen::VectorXd::Constant(D, D == 3 ? 0.8 : 3.0), 1.3);
      MatL Kmm = k(Z).cast<long double>();
      Kmm.diagonal().array() += static_cast<long double>(gp.fit_info().jitter_used * 1.3);
      const MatL Kmn = k(Z, X).cast<long double>();
      const MatL Kmm_inv = Kmm.inverse();
      const Eigen::Array<long double, Eigen::Dynamic, 1> lam =
          1.3L - (Kmn.transpose() * Kmm_inv * Kmn).diagonal().array() + 0.05L;
      const MatL KmnL = Kmn * lam.inverse().matrix().asDiagonal();
      const MatL Sigma = (Kmm + KmnL * Kmn.transpose()).inverse();
      const BlockwiseSparseGP blockwise(gp);
      for (const int ns : {1, 23, 24, 25, 301}) {
        Eigen::MatrixXd Xs, Ys;
        make_data(ns, D, 2, 50 + ns, Xs, Ys);
        const MatL Ksm = k(Xs, Z).cast<long double>();
        const Eigen::MatrixXd mean = (Ksm * Sigma * KmnL * Y.cast<long double>()).cast<double>();
        const Eigen::VectorXd var =
            (1.3L - (Ksm * (Kmm_inv - Sigma) * Ksm.transpose()).diagonal().array()).matrix().cast<double>();
        Eigen::MatrixXd m, v, mb, vb;
        gp.predict(Xs, m, v);
        blockwise.predict(Xs, mb, vb);
        ASSERT_EQ(m.rows(), ns);
        for (int p = 0; p < 2; ++p) EXPECT_LT((v.col(p) - var).cwiseAbs().maxCoeff(), 1e-8) << ns;
        EXPECT_LT((m - mean).cwiseAbs().maxCoeff(), 1e-7) << ns;
        // fused vs blockwise: the same algebra in another summation order
        EXPECT_LT((v - vb).cwiseAbs().maxCoeff(), 1e-12 * 1.3) << ns;
        EXPECT_LT((m - mb).cwiseAbs().maxCoeff(), 1e-10) << ns;
        EXPECT_LT((gp.predict_mean(Xs) - m).cwiseAbs().maxCoeff(), 1e-10);
        // with noise: var + noise
        Eigen::MatrixXd mn, vn;
        gp.predict(Xs, mn, vn, Predictive::Observation);
        EXPECT_LT(((vn - v).array() - 0.05).abs().maxCoeff(), 1e-12);
      }
    }
}

TEST(GPFitc, FusedVarianceNearZeroIsClampedNeverNaN) {
  // Inducing = training inputs (duplicated), zero noise: the predictive variance at the training
  // inputs is ~0 (rounding may push 1 - |G f|^2 below zero); it must come back >= 0 and finite,
  // agree with the exact GP and with the blockwise path.
  auto [X, Y, Xd, Yd, o] = duplicated_noise_free(40, 3, 77);
  o.inducing = X;
  SparseGP gp(o);
  gp.fit(Xd, Yd);
  Eigen::MatrixXd m, v, mb, vb;
  gp.predict(Xd, m, v);
  ASSERT_TRUE(v.allFinite());
  ASSERT_TRUE(m.allFinite());
  EXPECT_GE(v.minCoeff(), 0.0);
  EXPECT_LT(v.maxCoeff(), 1e-5 * 1.3);
  BlockwiseSparseGP(gp).predict(Xd, mb, vb);
  EXPECT_LT((v - vb).cwiseAbs().maxCoeff(), 1e-12 * 1.3);
  EXPECT_TRUE(gp.log_predictive_density(Xd, Yd).allFinite());
  // exact GP with the same zero noise (it adds jitter): same near-zero variances
  o.inducing.resize(0, 0);
  ExactGP ex(o);
  ex.fit(X, Y);
  Eigen::MatrixXd me, ve;
  ex.predict(X, me, ve);
  EXPECT_LT((ve - v.topRows(40)).cwiseAbs().maxCoeff(), 1e-5 * 1.3);
  EXPECT_LT((me - m.topRows(40)).cwiseAbs().maxCoeff(), 1e-4);
}

TEST(GPPredict, SingleOutputMeanKernelMatchesStdExpToAFewUlp) {
  // One training point, zero mean: mean(x) = alpha * variance * exp(-d^2 / 2), d the scaled
  // distance to it; the single-output mean path sums its own vectorised exp. Sweep d over
  // [0, 40] (exp down to 1e-348, i.e. through the subnormal range to 0) at 2,001 inputs (not
  // a multiple of the input group) and compare with std::exp, relative to exp's conditioning.
  for (const int D : {1, 3}) {
    GPOptions o = fixed_options();
    o.lengthscale = Eigen::VectorXd::Constant(1, 0.7);
    ExactGP gp(o);
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(1, D), Y(1, 1);
    Y << 2.0;
    gp.fit(X, Y);
    const double alpha = 2.0 / (1.3 + 0.05);
    const int n = 2001;
    Eigen::MatrixXd Xs = Eigen::MatrixXd::Zero(n, D);
    for (int i = 0; i < n; ++i) Xs(i, 0) = 0.7 * 40.0 * i / (n - 1);
    const Eigen::MatrixXd m = gp.predict_mean(Xs);
    double worst = 0.0;
    for (int i = 0; i < n; ++i) {
      const double d = Xs(i, 0) / 0.7;
      const double ref = alpha * 1.3 * std::exp(-0.5 * d * d);
      ASSERT_TRUE(std::isfinite(m(i, 0)));
      // exp's condition number is |x|: the exponent itself carries ~1 ulp * |x| of rounding
      if (ref > 1e-300) worst = std::max(worst, std::abs(m(i, 0) - ref) / ref / (1.0 + 0.5 * d * d));
      else EXPECT_LT(std::abs(m(i, 0)), 1e-290) << d;
    }
    EXPECT_LT(worst, 8 * std::numeric_limits<double>::epsilon()) << "D=" << D;
    // the fused mean + variance path builds its kernel vectors with the same exp
    Eigen::MatrixXd mv, vv;
    gp.predict(Xs, mv, vv);
    EXPECT_LT((mv - m).cwiseAbs().maxCoeff(), 1e-15);
  }
}

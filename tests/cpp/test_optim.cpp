// Tests of the optimisers: global optimisers on Rastrigin/Ackley within a stated budget (fixed
// seeds), local optimisers on problems with known minimisers, bookkeeping and bad input.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include <cmath>

#include "bayesgrasp/optim/annealing.hpp"
#include "bayesgrasp/optim/firefly.hpp"
#include "bayesgrasp/optim/pso.hpp"
#include "bayesgrasp/optim/trust_region.hpp"

using namespace bayesgrasp::optim;

namespace {
Bounds box(int d, double lo, double hi) {
  return Bounds{Eigen::VectorXd::Constant(d, lo), Eigen::VectorXd::Constant(d, hi)};
}
// Global minimum of Rastrigin and Ackley: f = 0 at the origin; the nearest local minima of
// Rastrigin have f ~ 1 and of Ackley f ~ 2.6, so f < 1e-3 means the global basin was found.
constexpr double kSolved = 1e-3;

// Runs run(seed) for seeds 0-9 and counts the seeds for which it returns true (solved).
template <class Run>
int solved_of_ten_seeds(Run run) {
  int solved = 0;
  for (std::uint64_t seed = 0; seed < 10; ++seed) solved += run(seed) ? 1 : 0;
  return solved;
}
}  // namespace

TEST(OptimPSO, Rastrigin4DWithin16kEvaluations) {
  // Budget: 40 particles x 400 iterations = 16,040 evaluations; 10 fixed seeds, 9 must succeed.
  const int solved = solved_of_ten_seeds([](std::uint64_t seed) {
    PSOOptions o;
    o.n_particles = 40;
    o.max_iter = 400;
    o.seed = seed;
    const Result r = pso(rastrigin, box(4, -5.12, 5.12), o);
    EXPECT_LE(r.evaluations, 16040);
    return r.f < kSolved && r.x.norm() < 1e-2;
  });
  EXPECT_GE(solved, 9) << "PSO solved 4-D Rastrigin for only " << solved << " of 10 seeds";
}

TEST(OptimPSO, Ackley4DWithin8kEvaluations) {
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    PSOOptions o;
    o.n_particles = 40;
    o.max_iter = 200;
    o.seed = seed;
    const Result r = pso(ackley, box(4, -32.768, 32.768), o);
    EXPECT_LT(r.f, kSolved) << "seed " << seed;
    EXPECT_EQ(r.evaluations, 40 * 201);
  }
}

TEST(OptimPSO, BookkeepingHistoryAndDeterminism) {
  PSOOptions o;
  o.n_particles = 10;
  o.max_iter = 30;
  o.seed = 7;
  o.record_history = true;
  const Result a = pso(sphere, box(3, -1, 2), o), b = pso(sphere, box(3, -1, 2), o);
  EXPECT_EQ(a.iterations, 30);
  EXPECT_EQ(a.evaluations, 10 * 31);
  ASSERT_EQ(a.history.size(), 31u);
  for (size_t i = 1; i < a.history.size(); ++i) EXPECT_LE(a.history[i], a.history[i - 1]);
  EXPECT_DOUBLE_EQ(a.history.back(), a.f);
  EXPECT_EQ(a.x, b.x);  // same seed, same result
  o.seed = 8;
  EXPECT_NE(pso(sphere, box(3, -1, 2), o).x, a.x);
}

TEST(OptimPSO, TargetStopsEarlyAndBoundsHold) {
  PSOOptions o;
  o.target = 1e-2;
  o.seed = 1;
  const Result r = pso(sphere, box(2, -1, 1), o);
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.f, 1e-2);
  EXPECT_LT(r.iterations, o.max_iter);
  // Minimiser outside the box: (x - 3)^2 on [-1, 1] is minimised at the upper bound.
  auto shifted = [](const RowMatrixXd& X, Eigen::VectorXd& f) { f = (X.array() - 3.0).square().rowwise().sum(); };
  const Result s = pso(shifted, box(2, -1, 1), PSOOptions{});
  EXPECT_NEAR(s.x[0], 1.0, 1e-9);
  EXPECT_NEAR(s.x[1], 1.0, 1e-9);
}

TEST(OptimPSO, StallStopsAfterStallIterWithoutImprovement) {
  // A constant objective never improves: the run stops after exactly stall_iter iterations.
  auto flat = [](const RowMatrixXd& X, Eigen::VectorXd& f) { f.setConstant(1.0); };
  PSOOptions o;
  o.stall_iter = 5;
  const Result r = pso(flat, box(2, 0, 1), o);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 5);
  EXPECT_EQ(r.evaluations, 40 * 6);
}

TEST(OptimPSO, NonFiniteValuesNeverBest) {
  auto f = [](const RowMatrixXd& X, Eigen::VectorXd& v) {
    for (Eigen::Index i = 0; i < X.rows(); ++i) v[i] = X(i, 0) < 0 ? std::nan("") : X.row(i).squaredNorm();
  };
  const Result r = pso(f, box(2, -1, 1), PSOOptions{});
  EXPECT_TRUE(std::isfinite(r.f));
  EXPECT_GE(r.x[0], 0.0);
}

TEST(OptimAnnealing, Rastrigin2DWithin16kEvaluations) {
  // Defaults: 16 chains x 1000 iterations = 16,016 evaluations, cooling 0.98, adaptive steps.
  // A run that misses ends in a neighbouring minimum (f ~ 0.995); asserted: at least 8 of
  // seeds 0-9, and never worse than the second ring of local minima.
  const int solved = solved_of_ten_seeds([](std::uint64_t seed) {
    AnnealingOptions o;
    o.seed = seed;
    const Result r = simulated_annealing(rastrigin, box(2, -5.12, 5.12), o);
    EXPECT_EQ(r.evaluations, 16 * 1001);
    EXPECT_LT(r.f, 2.0);  // never worse than the second ring of local minima
    return r.f < kSolved;
  });
  EXPECT_GE(solved, 8) << "SA solved 2-D Rastrigin for only " << solved << " of 10 seeds";
}

TEST(OptimAnnealing, Ackley3DWithin16kEvaluations) {
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    AnnealingOptions o;
    o.seed = seed;
    const Result r = simulated_annealing(ackley, box(3, -32.768, 32.768), o);
    EXPECT_LT(r.f, kSolved) << "seed " << seed;
    EXPECT_LT(r.x.norm(), 1e-3) << "seed " << seed;
  }
}

TEST(OptimAnnealing, AdaptiveStepRefines) {
  // With the step fixed at 10% of the range the chains cannot refine below ~1e-2 on the sphere;
  // the adapted step gets within 1e-4.
  AnnealingOptions o;
  o.seed = 3;
  const Result adaptive = simulated_annealing(sphere, box(2, -1, 1), o);
  o.adapt_interval = 0;
  const Result fixed = simulated_annealing(sphere, box(2, -1, 1), o);
  EXPECT_LT(adaptive.f, 1e-8);
  EXPECT_GT(fixed.f, adaptive.f);
}

TEST(OptimFirefly, Ackley2DAnd3DWithin10kEvaluations) {
  for (int d : {2, 3})
    for (std::uint64_t seed = 0; seed < 10; ++seed) {
      FireflyOptions o;
      o.n_fireflies = 25;
      o.max_iter = 400;  // 25 x 401 = 10,025 evaluations
      o.seed = seed;
      const Result r = firefly(ackley, box(d, -32.768, 32.768), o);
      EXPECT_EQ(r.evaluations, 25 * 401);
      EXPECT_LT(r.f, kSolved) << "dimension " << d << " seed " << seed;
    }
}

TEST(OptimFirefly, Rastrigin2DWithin20kEvaluations) {
  // The firefly algorithm is weak on Rastrigin (the swarm collapses onto the brightest
  // firefly's basin): with 100 fireflies x 200 generations, gamma = 30 (unit box), alpha = 0.2
  // decaying by 0.97, many seeds end in a neighbouring minimum. Asserted: at least 4 of seeds
  // 0-9 reach the global minimum, and none is worse than f = 2.
  const int solved = solved_of_ten_seeds([](std::uint64_t seed) {
    FireflyOptions o;
    o.n_fireflies = 100;
    o.max_iter = 200;
    o.gamma = 30.0;
    o.seed = seed;
    const Result r = firefly(rastrigin, box(2, -5.12, 5.12), o);
    EXPECT_LT(r.f, 2.0);
    return r.f < kSolved;
  });
  EXPECT_GE(solved, 4) << "firefly solved 2-D Rastrigin for only " << solved << " of 10 seeds";
}

TEST(OptimDescent, ConvexQuadraticReachesKnownMinimiser) {
  // f = 1/2 (x - c)^T A (x - c), A = diag(1, 4, 10): minimiser c, minimum 0.
  const Eigen::Vector3d c(0.5, -1.0, 2.0), a(1.0, 4.0, 10.0);
  auto f = [&](const RowMatrixXd& X, Eigen::VectorXd& v) {
    for (Eigen::Index i = 0; i < X.rows(); ++i)
      v[i] = 0.5 * ((X.row(i).transpose() - c).array().square() * a.array()).sum();
  };
  DescentOptions o;
  o.record_history = true;
  const Result r = steepest_descent(f, Eigen::Vector3d(3, 3, -3), Bounds{}, o);
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_LT((r.x - c).norm(), 1e-5);
  EXPECT_LT(r.f, 1e-10);
  for (size_t i = 1; i < r.history.size(); ++i) EXPECT_LE(r.history[i], r.history[i - 1]);
}

TEST(OptimDescent, ProjectedOntoBox) {
  auto f = [](const RowMatrixXd& X, Eigen::VectorXd& v) { v = (X.array() - 3.0).square().rowwise().sum(); };
  const Result r = steepest_descent(f, Eigen::Vector2d(0, 0), box(2, -1, 1));
  EXPECT_NEAR(r.x[0], 1.0, 1e-9);
  EXPECT_NEAR(r.x[1], 1.0, 1e-9);
}

TEST(OptimLM, RosenbrockResiduals) {
  // r = (10 (x2 - x1^2), 1 - x1): 1/2 |r|^2 is half the Rosenbrock function, minimiser (1, 1).
  auto res = [](const RowMatrixXd& X, RowMatrixXd& R) {
    R.resize(X.rows(), 2);
    for (Eigen::Index i = 0; i < X.rows(); ++i) {
      R(i, 0) = 10.0 * (X(i, 1) - X(i, 0) * X(i, 0));
      R(i, 1) = 1.0 - X(i, 0);
    }
  };
  const Result r = levenberg_marquardt(res, Eigen::Vector2d(-1.2, 1.0), Bounds{});
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_NEAR(r.x[0], 1.0, 1e-7);
  EXPECT_NEAR(r.x[1], 1.0, 1e-7);
  EXPECT_LT(r.iterations, 100);
}

TEST(OptimLM, LinearLeastSquaresMatchesNormalEquations) {
  Eigen::MatrixXd A(5, 2);
  A << 1, 0, 1, 1, 1, 2, 1, 3, 1, 4;
  Eigen::VectorXd y(5);
  y << 0.1, 0.9, 2.2, 2.9, 4.1;
  auto res = [&](const RowMatrixXd& X, RowMatrixXd& R) {
    R.resize(X.rows(), 5);
    for (Eigen::Index i = 0; i < X.rows(); ++i) R.row(i) = (A * X.row(i).transpose() - y).transpose();
  };
  const Eigen::VectorXd expect = (A.transpose() * A).ldlt().solve(A.transpose() * y);
  const Result r = levenberg_marquardt(res, Eigen::Vector2d(5, -5), Bounds{});
  EXPECT_LT((r.x - expect).norm(), 1e-8);
  EXPECT_NEAR(r.f, 0.5 * (A * expect - y).squaredNorm(), 1e-12);
}

TEST(OptimTrustRegion, RosenbrockScalar) {
  TrustRegionOptions o;
  o.max_iter = 500;
  const Result r = trust_region(rosenbrock, Eigen::Vector2d(-1.2, 1.0), Bounds{}, o);
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_NEAR(r.x[0], 1.0, 1e-5);
  EXPECT_NEAR(r.x[1], 1.0, 1e-5);
}

TEST(OptimTrustRegion, GaussianPosteriorMode) {
  // Eq. 4.4-like objective: -log N(m | x, s^2) - log N(x | mu0, S0) in 3-D; the mode is the
  // precision-weighted mean (s^-2 m + S0^-1 mu0) / (s^-2 + S0^-1) per dimension.
  const Eigen::Vector3d m(1.0, -0.5, 0.3), mu0(0.0, 0.0, 0.0), s2(0.01, 0.04, 0.02), p2(0.09, 0.09, 0.25);
  auto f = [&](const RowMatrixXd& X, Eigen::VectorXd& v) {
    for (Eigen::Index i = 0; i < X.rows(); ++i) {
      const Eigen::Array3d x = X.row(i).transpose().array();
      v[i] = 0.5 * ((x - m.array()).square() / s2.array()).sum() + 0.5 * ((x - mu0.array()).square() / p2.array()).sum();
    }
  };
  const Eigen::Vector3d expect = ((m.array() / s2.array() + mu0.array() / p2.array()) /
                                  (1.0 / s2.array() + 1.0 / p2.array())).matrix();
  const Result r = trust_region(f, Eigen::Vector3d(0.2, 0.2, 0.2), Bounds{});
  EXPECT_LT((r.x - expect).norm(), 1e-6);
}

TEST(OptimBadInput, Rejected) {
  Bounds b{Eigen::Vector2d(0, 1), Eigen::Vector2d(1, 0)};  // low > high in dim 1
  EXPECT_THROW(pso(sphere, b), std::invalid_argument);
  EXPECT_THROW(simulated_annealing(sphere, b), std::invalid_argument);
  EXPECT_THROW(firefly(sphere, b), std::invalid_argument);
  Bounds nan{Eigen::Vector2d(0, std::nan("")), Eigen::Vector2d(1, 1)};
  EXPECT_THROW(pso(sphere, nan), std::invalid_argument);
  PSOOptions o;
  o.n_particles = 0;
  EXPECT_THROW(pso(sphere, box(2, 0, 1), o), std::invalid_argument);
  o = PSOOptions{};
  o.c1 = std::nan("");
  EXPECT_THROW(pso(sphere, box(2, 0, 1), o), std::invalid_argument);
  o = PSOOptions{};
  o.init = RowMatrixXd::Constant(o.n_particles, 2, std::nan(""));  // the right shape, not finite
  EXPECT_THROW(pso(sphere, box(2, 0, 1), o), std::invalid_argument);
  AnnealingOptions a;
  a.init = RowMatrixXd::Zero(a.n_chains + 1, 2);
  EXPECT_THROW(simulated_annealing(sphere, box(2, 0, 1), a), std::invalid_argument);
  EXPECT_THROW(steepest_descent(sphere, Eigen::Vector2d(std::nan(""), 0), Bounds{}), std::invalid_argument);
  EXPECT_THROW(steepest_descent(sphere, Eigen::Vector3d(0, 0, 0), box(2, 0, 1)), std::invalid_argument);
  EXPECT_THROW(builtin_objective("nope"), std::invalid_argument);
}

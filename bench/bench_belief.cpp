// Belief throughput: a full update cycle (reweight by a cheap likelihood + systematic resampling +
// one Metropolis sweep + roughening) in particles/s; the expected posterior entropy (Eq. 3.2) of
// one action for 500 particles x 100 samples, and of 64 actions in one batch call; KDE entropy;
// the relative-pose transform. One thread.
#include <benchmark/benchmark.h>

#include <cmath>

#include "bayesgrasp/belief/entropy.hpp"
#include "bayesgrasp/belief/particles.hpp"
#include "bayesgrasp/belief/relative_pose.hpp"

using namespace bayesgrasp::belief;

namespace {
// Cheap likelihood: Gaussian around a pose (x, y, yaw), yaw difference wrapped.
void cheap(const RowMatrixXd& X, Eigen::VectorXd& ll) {
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const double dx = (X(i, 0) - 0.02) / 0.01, dy = (X(i, 1) + 0.01) / 0.01;
    const double dyaw = std::remainder(X(i, 2) - 0.3, 2.0 * M_PI) / 0.1;
    ll[i] = -0.5 * (dx * dx + dy * dy + dyaw * dyaw);
  }
}
}  // namespace

static void BM_BeliefUpdateCycle(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0));
  Rng rng(0);
  const auto space = StateSpace::planar_pose(-0.1, 0.1, -0.1, 0.1);
  ParticleBelief b = ParticleBelief::uniform(space, n, rng);
  const Eigen::Vector3d step(0.005, 0.005, 0.05);
  for (auto _ : st) {
    b.update(cheap);
    b.resample(rng, Resampling::Systematic);
    b.metropolis(cheap, step, 1, rng);
    b.roughen(rng, 0.2);
    benchmark::DoNotOptimize(b.particles().data());
  }
  st.counters["particles_per_s"] = benchmark::Counter(static_cast<double>(n) * st.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BeliefUpdateCycle)->Arg(500)->Arg(5000)->Arg(50000)->Unit(benchmark::kMicrosecond);

namespace {
void epe_inputs(int n, int A, int K, Eigen::VectorXd& lw, RowMatrixXd& mean, RowMatrixXd& var) {
  Rng rng(1);
  lw.resize(n);
  for (int i = 0; i < n; ++i) lw[i] = -uniform01(rng);
  mean.resize(static_cast<Eigen::Index>(A) * n, K);
  var.resize(static_cast<Eigen::Index>(A) * n, K);
  for (Eigen::Index r = 0; r < mean.rows(); ++r)
    for (int k = 0; k < K; ++k) { mean(r, k) = uniform01(rng); var(r, k) = 0.01 + 0.05 * uniform01(rng); }
}
}  // namespace

static void BM_ExpectedEntropy_500x100(benchmark::State& st) {
  const int K = static_cast<int>(st.range(0));
  Eigen::VectorXd lw;
  RowMatrixXd mean, var;
  epe_inputs(500, 1, K, lw, mean, var);
  for (auto _ : st) benchmark::DoNotOptimize(expected_posterior_entropy(lw, mean, var, 100, 7).mean);
}
BENCHMARK(BM_ExpectedEntropy_500x100)->ArgName("outputs")->Arg(1)->Arg(3)->Arg(6)->Unit(benchmark::kMicrosecond);

static void BM_ExpectedEntropyBatch64_500x100(benchmark::State& st) {
  const int K = 3, A = 64;
  Eigen::VectorXd lw;
  RowMatrixXd mean, var;
  epe_inputs(500, A, K, lw, mean, var);
  for (auto _ : st) benchmark::DoNotOptimize(expected_posterior_entropy_batch(lw, mean, var, A, 100, 7, 1)[0].mean);
  st.counters["actions_per_s"] = benchmark::Counter(static_cast<double>(A) * st.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ExpectedEntropyBatch64_500x100)->Unit(benchmark::kMillisecond);

static void BM_KDEEntropy(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0));
  Rng rng(2);
  const auto space = StateSpace::planar_pose(-0.1, 0.1, -0.1, 0.1);
  const ParticleBelief b = ParticleBelief::uniform(space, n, rng);
  for (auto _ : st) benchmark::DoNotOptimize(kde_entropy(b.particles(), b.log_weights(), space));
}
BENCHMARK(BM_KDEEntropy)->Arg(500)->Unit(benchmark::kMicrosecond);

static void BM_RelativePose_64x500(benchmark::State& st) {
  Rng rng(3);
  RowMatrixXd A(64, 3), P(500, 3);
  for (Eigen::Index i = 0; i < A.size(); ++i) A.data()[i] = uniform01(rng);
  for (Eigen::Index i = 0; i < P.size(); ++i) P.data()[i] = uniform01(rng);
  for (auto _ : st) benchmark::DoNotOptimize(relative_planar_pose(A, P).data());
  st.counters["pairs_per_s"] = benchmark::Counter(64.0 * 500 * st.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RelativePose_64x500)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();

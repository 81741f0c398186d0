// Optimiser overhead: time per candidate evaluation with a trivial C++ objective (so the figure
// is the optimiser's own bookkeeping: random numbers, velocity/position updates, bests), and with
// cheap real objectives for reference. Counter ns_per_eval = wall time / evaluations.
#include <benchmark/benchmark.h>

#include "bayesgrasp/optim/annealing.hpp"
#include "bayesgrasp/optim/firefly.hpp"
#include "bayesgrasp/optim/pso.hpp"

using namespace bayesgrasp::optim;

namespace {
Bounds box(int d) { return Bounds{Eigen::VectorXd::Constant(d, -5.0), Eigen::VectorXd::Constant(d, 5.0)}; }
// Trivial objective: f = x_0 (reads one number per candidate; keeps the swarm moving).
void trivial(const RowMatrixXd& X, Eigen::VectorXd& f) { f = X.col(0); }

void report(benchmark::State& st, long long evals) {
  st.counters["evals"] = static_cast<double>(evals);
  st.counters["ns_per_eval"] = benchmark::Counter(
      static_cast<double>(evals) * st.iterations(), benchmark::Counter::kIsRate | benchmark::Counter::kInvert,
      benchmark::Counter::OneK::kIs1000);
}

// Times one run of `optimise` (a callable returning a Result) per benchmark iteration.
template <class Optimise>
void time_runs(benchmark::State& st, Optimise optimise) {
  long long evals = 0;
  for (auto _ : st) {
    const Result r = optimise();
    benchmark::DoNotOptimize(r.f);
    evals = r.evaluations;
  }
  report(st, evals);
}

// 40 particles x 1000 swarm updates.
PSOOptions swarm() {
  PSOOptions o;
  o.n_particles = 40;
  o.max_iter = 1000;
  return o;
}
}  // namespace

static void BM_PSO_Overhead(benchmark::State& st) {
  const Bounds b = box(static_cast<int>(st.range(0)));
  time_runs(st, [&] { return pso(trivial, b, swarm()); });
}
BENCHMARK(BM_PSO_Overhead)->Arg(2)->Arg(4)->Arg(10)->Unit(benchmark::kMillisecond);

static void BM_PSO_Rastrigin(benchmark::State& st) {
  const Bounds b = box(static_cast<int>(st.range(0)));
  time_runs(st, [&] { return pso(rastrigin, b, swarm()); });
}
BENCHMARK(BM_PSO_Rastrigin)->Arg(4)->Unit(benchmark::kMillisecond);

static void BM_Annealing_Overhead(benchmark::State& st) {
  const Bounds b = box(static_cast<int>(st.range(0)));
  time_runs(st, [&] { return simulated_annealing(trivial, b, AnnealingOptions{}); });
}
BENCHMARK(BM_Annealing_Overhead)->Arg(4)->Unit(benchmark::kMillisecond);

static void BM_Firefly_Overhead(benchmark::State& st) {
  const Bounds b = box(static_cast<int>(st.range(0)));
  FireflyOptions o;
  o.n_fireflies = 25;
  o.max_iter = 400;
  time_runs(st, [&] { return firefly(trivial, b, o); });
}
BENCHMARK(BM_Firefly_Overhead)->Arg(4)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();

// Grasp quality: epsilon + GWS volume per grasp (Qhull in 6-D), one core; also epsilon only.
// Grasps: k contacts (4..7) on an ellipsoid of semi-axes 4, 3, 2 cm, seeded; mu = 0.5,
// 8 friction-cone edges (the defaults), torque scale 4 cm. The figure is the time of one
// grasp_quality call (wrench construction + hull + epsilon + volume), averaged over a
// fixed pool of 64 seeded grasps that includes force-closure and non-closure grasps.
#include <benchmark/benchmark.h>

#include <random>

#include "bayesgrasp/quality/wrench_space.hpp"

using namespace bayesgrasp;

namespace {

std::vector<Contacts> grasp_pool(int k, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const Vec3 axes(0.04, 0.03, 0.02);
  std::vector<Contacts> pool;
  for (int i = 0; i < n; ++i) {
    Contacts cs;
    for (int j = 0; j < k; ++j) {
      const Vec3 u = Vec3(g(rng), g(rng), g(rng)).normalized();
      Contact c;
      c.point = axes.cwiseProduct(u);
      c.normal = c.point.cwiseQuotient(axes.cwiseProduct(axes)).normalized();
      cs.push_back(c);
    }
    pool.push_back(cs);
  }
  return pool;
}

void BM_EpsilonVolume(benchmark::State& state) {
  const int k = static_cast<int>(state.range(0));
  const auto pool = grasp_pool(k, 64, 1234 + k);
  QualityParams prm;
  prm.n_edges = static_cast<int>(state.range(1));
  prm.volume = state.range(2) != 0;
  size_t i = 0;
  int closed = 0;
  for (auto _ : state) {
    const GraspQuality q = grasp_quality(pool[i % pool.size()], Vec3::Zero(), 0.04, prm);
    benchmark::DoNotOptimize(q);
    closed += q.epsilon > 0;
    ++i;
  }
  state.counters["contacts"] = k;
  state.counters["edges"] = prm.n_edges;
  state.counters["volume"] = prm.volume;
  state.counters["force_closure_fraction"] = static_cast<double>(closed) / static_cast<double>(i);
  state.SetItemsProcessed(static_cast<int64_t>(i));
}

}  // namespace

// Args: contacts, cone edges, volume on/off (off: epsilon only, as for auto-grasp + epsilon).
BENCHMARK(BM_EpsilonVolume)
    ->ArgsProduct({{2, 3, 4, 5, 6, 7}, {8}, {1}})
    ->Args({4, 8, 0})
    ->Args({5, 8, 0})
    ->Args({5, 4, 1})
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();

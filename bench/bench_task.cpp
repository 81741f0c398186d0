// Eq. 4.1's objective: (candidate, model grasp) pairs per second of the grasp mixture (Laplace and
// regularised Gaussian), the per-model shares, and the open hand's clearance against a cloud.
// One thread.
#include <benchmark/benchmark.h>

#include <random>

#include "bayesgrasp/task/grasp_mixture.hpp"
#include "bayesgrasp/task/hand_clearance.hpp"

using namespace bayesgrasp;
using namespace bayesgrasp::task;

namespace {
std::vector<Iso3> random_poses(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Iso3> out(static_cast<size_t>(n));
  for (Iso3& T : out) {
    const Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
    T = Iso3::Identity();
    T.linear() = q.normalized().toRotationMatrix();
    T.translation() = 0.05 * Vec3(g(rng), g(rng), g(rng));
  }
  return out;
}

GraspMixture mixture(int models, int per_model) {
  const std::vector<Iso3> grasps = random_poses(models * per_model, 1);
  std::vector<int> owner;
  for (int i = 0; i < models; ++i)
    for (int k = 0; k < per_model; ++k) owner.push_back(i);
  return GraspMixture(grasps, Eigen::VectorXd::Constant(models * per_model, 0.1), owner, models);
}

void run_mixture(benchmark::State& st, DensityKind kind, bool per_model) {
  const GraspMixture mix = mixture(6, static_cast<int>(st.range(0)));
  const std::vector<Iso3> candidates = random_poses(1024, 2);
  PoseDensity d;
  d.kind = kind;
  for (auto _ : st) benchmark::DoNotOptimize(mix.evaluate(candidates, d, per_model, 1).value.data());
  st.counters["pairs_per_s"] =
      benchmark::Counter(static_cast<double>(candidates.size()) * mix.size() * st.iterations(), benchmark::Counter::kIsRate);
}
}  // namespace

static void BM_MixtureLaplace(benchmark::State& st) { run_mixture(st, DensityKind::Laplace, false); }
static void BM_MixtureRegularised(benchmark::State& st) { run_mixture(st, DensityKind::RegularisedGaussian, false); }
static void BM_MixtureLaplacePerModel(benchmark::State& st) { run_mixture(st, DensityKind::Laplace, true); }
BENCHMARK(BM_MixtureLaplace)->Arg(5)->Arg(50)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MixtureRegularised)->Arg(5)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MixtureLaplacePerModel)->Arg(5)->Unit(benchmark::kMicrosecond);

static void BM_HandClearance(benchmark::State& st) {
  const HandModel hand = HandModel::from_file(std::string(BAYESGRASP_SOURCE_DIR) + "/python/bayesgrasp/data/hands/barrett_bh8.json");
  const Eigen::VectorXd q = hand.coupled_joints(0.5, 0.0);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  CloudPoints cloud(static_cast<Eigen::Index>(st.range(0)), 3);
  for (Eigen::Index i = 0; i < cloud.rows(); ++i) cloud.row(i) << u(rng), u(rng), 0.05 + u(rng);
  std::vector<Iso3> poses = random_poses(32, 4);
  for (Iso3& T : poses) T.translation() += Vec3(0, 0, 0.15);
  for (auto _ : st) benchmark::DoNotOptimize(hand_clearance(hand, q, poses, cloud, {}, 1).cloud.data());
  st.counters["poses_per_s"] = benchmark::Counter(32.0 * st.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HandClearance)->Arg(1000)->Arg(4000)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();

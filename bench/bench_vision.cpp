// Ray-casting throughput of the simulated depth camera (rays/s, one 640 x 480 frame per
// iteration) on a scene of a finely tessellated sphere, a box and the table, noise on and off.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "bayesgrasp/vision/camera.hpp"

using namespace bayesgrasp;
using namespace bayesgrasp::vision;

namespace {
TriMesh uv_sphere(const Vec3& c, double r, int nu, int nv) {
  TriMesh m;
  m.V.resize(2 + (nv - 1) * nu, 3);
  m.V.row(0) = (c + Vec3(0, 0, r)).transpose();
  m.V.row(1) = (c - Vec3(0, 0, r)).transpose();
  const double pi = 3.14159265358979323846;
  for (int i = 1; i < nv; ++i)
    for (int j = 0; j < nu; ++j) {
      const double th = pi * i / nv, ph = 2 * pi * j / nu;
      m.V.row(2 + (i - 1) * nu + j) = (c + r * Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th))).transpose();
    }
  std::vector<Eigen::Vector3i> F;
  auto id = [&](int i, int j) { return 2 + (i - 1) * nu + (j % nu); };
  for (int j = 0; j < nu; ++j) {
    F.emplace_back(0, id(1, j), id(1, j + 1));
    F.emplace_back(1, id(nv - 1, j + 1), id(nv - 1, j));
    for (int i = 1; i < nv - 1; ++i) {
      F.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      F.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  }
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t f = 0; f < F.size(); ++f) m.F.row(static_cast<Eigen::Index>(f)) = F[f].transpose();
  return m;
}

void BM_RenderFrame(benchmark::State& state) {
  const int nu = static_cast<int>(state.range(0));
  const bool noise = state.range(1) != 0;
  const std::vector<TriMesh> meshes = {uv_sphere(Vec3(0.05, 0, 0.08), 0.08, nu, nu / 2),
                                       uv_sphere(Vec3(-0.12, 0.05, 0.05), 0.05, nu, nu / 2)};
  const RayCaster caster(meshes);
  Intrinsics K;
  Table table;
  table.enabled = true;
  NoiseModel nm;
  nm.enabled = noise;
  const Iso3 cam = look_at(Vec3(0.5, -0.5, 0.5), Vec3(0, 0, 0.05));
  for (auto _ : state) {
    RenderResult r = render(K, cam, caster, table, nm);
    benchmark::DoNotOptimize(r.depth.data());
  }
  state.counters["triangles"] = static_cast<double>(caster.num_triangles());
  state.counters["rays_per_s"] = benchmark::Counter(static_cast<double>(K.width) * K.height * state.iterations(),
                                                    benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderFrame)->Args({64, 0})->Args({512, 0})->Args({512, 1})->Unit(benchmark::kMillisecond);
}  // namespace

BENCHMARK_MAIN();

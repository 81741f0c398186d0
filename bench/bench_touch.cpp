// One touch's estimate (Pub. I): the executed top grasp re-simulated 2,000 times (the evaluation
// budget) while an optimiser fits the object state to the readings, one core (Barrett BH8, table).
//
//   Estimate/<optimiser>/<object>   3 DoF (x, y, yaw); 4 DoF adds the scale (its simulators per
//                                   quantised scale built in the first iteration and kept)
// Objects: the 6 cm cube (12 triangles), and each --mesh=NAME=PATH, a mesh in the object's frame
// (see read_mesh; bench/run_touch.sh exports the library's cylinder and mug). Google Benchmark
// reports wall and CPU time per estimate; on a shared machine the CPU column is the one to read.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <string>

#include "bayesgrasp/touch/estimate.hpp"

using namespace bayesgrasp;
using namespace bayesgrasp::touch;

namespace {

const std::string kBarrett = std::string(BAYESGRASP_SOURCE_DIR) + "/python/bayesgrasp/data/hands/barrett_bh8.json";

/// The library's cube: 6 cm, centred on the z axis, standing on the table.
TriMesh cube() {
  TriMesh m;
  m.V.resize(8, 3);
  m.V << -0.03, -0.03, 0, 0.03, -0.03, 0, -0.03, 0.03, 0, 0.03, 0.03, 0,  //
      -0.03, -0.03, 0.06, 0.03, -0.03, 0.06, -0.03, 0.03, 0.06, 0.03, 0.03, 0.06;
  m.F.resize(12, 3);
  m.F << 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5;
  return m;
}

/// A mesh as plain numbers: "N M", then N vertex rows x y z, then M triangle rows a b c (0-based).
TriMesh read_mesh(const std::string& path) {
  std::ifstream in(path);
  long n = 0, m = 0;
  if (!(in >> n >> m) || n < 3 || m < 1) throw std::runtime_error("cannot read a mesh from " + path);
  TriMesh mesh;
  mesh.V.resize(n, 3);
  mesh.F.resize(m, 3);
  for (long i = 0; i < 3 * n; ++i) in >> mesh.V(i / 3, i % 3);
  for (long i = 0; i < 3 * m; ++i) in >> mesh.F(i / 3, i % 3);
  if (!in) throw std::runtime_error("truncated mesh file " + path);
  return mesh;
}

/// The objects: the cube, then the --mesh=NAME=PATH files in the order given.
std::vector<std::pair<std::string, TriMesh>> g_objects;

void BM_Estimate(benchmark::State& state) {
  const auto optimizer = static_cast<Optimizer>(state.range(0));
  const auto& [name, mesh] = g_objects[state.range(1)];
  const bool size = state.range(2) != 0;
  const HandModel hand = HandModel::from_file(kBarrett);
  const TouchModel model(hand, mesh);
  // the world: the object at (1 cm, -1.5 cm, 20 deg), scale 1.1 when the size is unknown
  const State truth(0.01, -0.015, 0.35, size ? 1.1 : 1.0);
  TriMesh world_mesh = mesh;
  world_mesh.V *= truth[3];
  const GraspSimulator world(hand, transformed(world_mesh, planar_pose(truth[0], truth[1], truth[2])));
  const State guess(-0.01, 0.005, 0.6, 1.0);
  const TouchGrasp grasp = TouchGrasp::top(guess[0], guess[1], guess[2], 0.0);
  const TouchReadings measured = readings_of(execute(world, grasp));
  EstimateOptions o;
  o.optimizer = optimizer;
  o.unknowns = size ? Unknowns::PoseAndScale : Unknowns::Pose;
  o.budget = 2000;
  double error = 0.0;
  for (auto _ : state) {
    const EstimateResult r = estimate(model, grasp, measured, guess, o);
    benchmark::DoNotOptimize(r.fitness);
    error = std::hypot(r.state[0] - truth[0], r.state[1] - truth[1]);
  }
  state.counters["evaluations"] = o.budget;
  state.counters["position_error_mm"] = 1e3 * error;
  const char* names[] = {"descent", "annealing", "pso", "firefly", "trust_region"};
  state.SetLabel(std::string(names[state.range(0)]) + ", " + name + (size ? ", 4 DoF" : ", 3 DoF"));
}

void args(benchmark::internal::Benchmark* b) {
  for (int opt : {static_cast<int>(Optimizer::PSO), static_cast<int>(Optimizer::Descent),
                  static_cast<int>(Optimizer::Annealing), static_cast<int>(Optimizer::Firefly)})
    for (int obj = 0; obj < static_cast<int>(g_objects.size()); ++obj) b->Args({opt, obj, 0});
  const int pso = static_cast<int>(Optimizer::PSO);
  for (int obj = 0; obj < static_cast<int>(g_objects.size()); ++obj) b->Args({pso, obj, 1});
}

}  // namespace

int main(int argc, char** argv) {
  g_objects.emplace_back("cube", cube());
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    const char* a = argv[i];
    const char* eq = std::strncmp(a, "--mesh=", 7) == 0 ? std::strchr(a + 7, '=') : nullptr;
    if (eq) g_objects.emplace_back(std::string(a + 7, eq), read_mesh(eq + 1));
    else rest.push_back(argv[i]);
  }
  benchmark::RegisterBenchmark("Estimate", BM_Estimate)
      ->Apply(args)
      ->ArgNames({"optimizer", "object", "size"})
      ->Unit(benchmark::kMillisecond);
  int n = static_cast<int>(rest.size());
  benchmark::Initialize(&n, rest.data());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

// One touch's estimate (Pub. I): the executed top grasp re-simulated 2,000 times (the evaluation
// budget) while an optimiser fits the object state to the readings, one core (Barrett BH8, table).
//
//   Estimate/<optimiser>/<object>   3 DoF (x, y, yaw); 4 DoF adds the scale (its simulators per
//                                   quantised scale built in the first iteration and kept)
// Objects: a 6 cm cube (12 triangles), a cylinder r = 3.5 cm, h = 12 cm (64 sides, 256
// triangles), and with --mesh=PATH a mesh in the object's frame (see read_mesh; bench/run_touch.sh
// exports the built-in mug). Google Benchmark reports wall and CPU time per estimate; on a shared machine
// the CPU column is the one to read.
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
std::string g_mesh;

TriMesh polygon_prism(int n, double r, double h, double phase) {
  TriMesh m;
  m.V.resize(2 * n, 3);
  m.F.resize(4 * n - 4, 3);
  for (int i = 0; i < n; ++i) {
    const double a = phase + 2 * M_PI * i / n;
    m.V.row(i) << r * std::cos(a), r * std::sin(a), 0.0;
    m.V.row(n + i) << r * std::cos(a), r * std::sin(a), h;
  }
  int f = 0;
  for (int i = 0; i < n; ++i) m.F.row(f++) << i, (i + 1) % n, n + (i + 1) % n, m.F.row(f++) << i, n + (i + 1) % n, n + i;
  for (int i = 1; i + 1 < n; ++i) m.F.row(f++) << 0, i + 1, i, m.F.row(f++) << n, n + i, n + i + 1;
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

TriMesh object(int which) {
  if (which == 0) return polygon_prism(4, 0.03 * std::sqrt(2.0), 0.06, M_PI / 4);
  if (which == 1) return polygon_prism(64, 0.035, 0.12, 0.0);
  return read_mesh(g_mesh);
}

const char* kObjects[] = {"cube", "cylinder", "mesh"};

void BM_Estimate(benchmark::State& state) {
  const auto optimizer = static_cast<Optimizer>(state.range(0));
  const int which = static_cast<int>(state.range(1));
  const bool size = state.range(2) != 0;
  if (which == 2 && g_mesh.empty()) {
    state.SkipWithError("no --mesh given");
    return;
  }
  const HandModel hand = HandModel::from_file(kBarrett);
  const TriMesh mesh = object(which);
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
  state.SetLabel(std::string(kObjects[which]) + (size ? ", 4 DoF" : ", 3 DoF"));
}

void args(benchmark::internal::Benchmark* b) {
  for (int opt : {static_cast<int>(Optimizer::PSO), static_cast<int>(Optimizer::Descent),
                  static_cast<int>(Optimizer::Annealing), static_cast<int>(Optimizer::Firefly)})
    for (int obj : {0, 1, 2}) b->Args({opt, obj, 0});
  for (int obj : {0, 1, 2}) b->Args({static_cast<int>(Optimizer::PSO), obj, 1});
}

}  // namespace

BENCHMARK(BM_Estimate)->Apply(args)->ArgNames({"optimizer", "object", "size"})->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    if (std::strncmp(argv[i], "--mesh=", 7) == 0) g_mesh = argv[i] + 7;
    else rest.push_back(argv[i]);
  }
  int n = static_cast<int>(rest.size());
  benchmark::Initialize(&n, rest.data());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

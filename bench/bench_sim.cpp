// Auto-grasp speed on a mug of about 2k triangles (Barrett BH8 hand, table at z = 0), one core.
//
//   TopGrasp/*        palm-down approach along -z to the first contact, then closing (what a
//                     planner calls): conservative advancement with FCL distance queries
//   Close/*           closing alone, from the hand poses the top grasps reached
//   CloseFixedStep    the same closing GraspIt!-style: 0.01-rad actuator steps with an FCL
//                     collision check each, bisection on a hit (same FCL backend, same grasps)
//   TopGraspBatch/threads:2   the batch call with two threads (wall-clock time)
//   Approach/0        approaches from random directions on the upper hemisphere (the hand
//                     moves down along -u for u uniform on the upper unit hemisphere), random
//                     rolls in [-pi, pi), targets within 1 cm of the object's box centre, then
//                     closing; many stop on the table (counter table_stops) because the open
//                     hand is wider than the mug is tall
//   Approach/1        the same approaches restricted to those that reach the object
// Single-core figures are per CPU second (the process's CPU time), so that other load on the
// machine does not distort them; the thread benchmark uses wall-clock time.
// Variants compare FCL representations: OBBRSS vs RSS bounding volumes for the object,
// capsule axes as sliver triangles vs capsule/box primitives (vs tessellated capsule meshes:
// variant 6, not run by default: far slower, see BENCHMARKS.md), exact queries vs an error allowance, and
// without the box / 26-DOP lower-bound culling.
//
// Extra flags (before Google Benchmark's own):
//   --grasps=N          number of random top grasps and approaches (default 256, seed 1)
//   --mesh=FILE         the object (an OBJ file) instead of the default mug below
//   --export=DIR        write DIR/mug.obj and DIR/sim_grasps.csv (hand pose, spread, our and
//                       the fixed-step joint angles) for the pybullet peer, and
//                       DIR/sim_agreement.json (joint-angle agreement, queries per grasp)
// The mesh is --mesh, else bench/data/mug.obj if it exists, else a generated closed mug-like
// mesh. bench/run_sim.sh runs the approach benchmarks on the built-in mug (exported by
// bench/world_export_mesh.py).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include "bayesgrasp/sim/grasp_simulator.hpp"

using namespace bayesgrasp;

namespace {

const std::string kSrc = BAYESGRASP_SOURCE_DIR;

TriMesh to_mesh(const std::vector<Vec3>& V, const std::vector<Eigen::Vector3i>& F) {
  TriMesh m;
  m.V.resize(static_cast<int>(V.size()), 3);
  for (size_t i = 0; i < V.size(); ++i) m.V.row(static_cast<int>(i)) = V[i].transpose();
  m.F.resize(static_cast<int>(F.size()), 3);
  for (size_t i = 0; i < F.size(); ++i) m.F.row(static_cast<int>(i)) = F[i].transpose();
  return m;
}

/// Closed mug-like mesh: cylinder body r = 4 cm, h = 9.5 cm (64 sides, 8 rings) and a
/// torus-segment handle (major radius 3 cm, tube 6 mm) whose capped ends sit inside the body.
TriMesh generated_mug() {
  std::vector<Vec3> V;
  std::vector<Eigen::Vector3i> F;
  const int n = 64, rings = 8;
  const double r = 0.04, h = 0.095;
  for (int k = 0; k <= rings; ++k)
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      V.emplace_back(r * std::cos(a), r * std::sin(a), h * k / rings);
    }
  const int bottom = static_cast<int>(V.size());
  V.emplace_back(0, 0, 0);
  const int top = static_cast<int>(V.size());
  V.emplace_back(0, 0, h);
  for (int k = 0; k < rings; ++k)
    for (int i = 0; i < n; ++i) {
      const int a = k * n + i, b = k * n + (i + 1) % n;
      F.emplace_back(a, b, b + n);
      F.emplace_back(a, b + n, a + n);
    }
  for (int i = 0; i < n; ++i) {
    F.emplace_back(bottom, (i + 1) % n, i);
    F.emplace_back(top, rings * n + i, rings * n + (i + 1) % n);
  }
  // handle: torus segment in the xz plane about (0.045, 0, 0.0475), from -100 to 100 deg
  const int along = 40, around = 12;
  const double R = 0.03, tube = 0.006;
  const Vec3 c(0.045, 0, 0.0475);
  const int h0 = static_cast<int>(V.size());
  for (int k = 0; k <= along; ++k) {
    const double u = (-100.0 + 200.0 * k / along) * M_PI / 180.0;
    const Vec3 center = c + R * Vec3(std::cos(u), 0, std::sin(u));
    const Vec3 radial(std::cos(u), 0, std::sin(u));
    for (int i = 0; i < around; ++i) {
      const double v = 2 * M_PI * i / around;
      V.push_back(center + tube * (std::cos(v) * radial + std::sin(v) * Vec3::UnitY()));
    }
  }
  for (int k = 0; k < along; ++k)
    for (int i = 0; i < around; ++i) {
      const int a = h0 + k * around + i, b = h0 + k * around + (i + 1) % around;
      F.emplace_back(a, b, b + around);
      F.emplace_back(a, b + around, a + around);
    }
  for (int end = 0; end < 2; ++end) {
    const double u = (end ? 100.0 : -100.0) * M_PI / 180.0;
    const int ci = static_cast<int>(V.size());
    V.push_back(c + R * Vec3(std::cos(u), 0, std::sin(u)));
    const int base = h0 + (end ? along : 0) * around;
    for (int i = 0; i < around; ++i) {
      if (end) F.emplace_back(ci, base + (i + 1) % around, base + i);
      else F.emplace_back(ci, base + i, base + (i + 1) % around);
    }
  }
  return to_mesh(V, F);
}

TriMesh read_obj(const std::string& path) {
  std::ifstream in(path);
  std::vector<Vec3> V;
  std::vector<Eigen::Vector3i> F;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string tag;
    ss >> tag;
    if (tag == "v") {
      Vec3 p;
      ss >> p.x() >> p.y() >> p.z();
      V.push_back(p);
    } else if (tag == "f") {
      std::vector<int> idx;
      std::string tok;
      while (ss >> tok) idx.push_back(std::stoi(tok.substr(0, tok.find('/'))) - 1);
      for (size_t k = 1; k + 1 < idx.size(); ++k) F.emplace_back(idx[0], idx[k], idx[k + 1]);
    }
  }
  return to_mesh(V, F);
}

void write_obj(const TriMesh& m, const std::string& path) {
  std::ofstream out(path);
  out.precision(9);
  for (int i = 0; i < m.V.rows(); ++i) out << "v " << m.V(i, 0) << " " << m.V(i, 1) << " " << m.V(i, 2) << "\n";
  for (int i = 0; i < m.F.rows(); ++i) out << "f " << m.F(i, 0) + 1 << " " << m.F(i, 1) + 1 << " " << m.F(i, 2) + 1 << "\n";
}

struct Setup {
  HandModel hand;
  TriMesh mug;
  std::string mug_source;
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> xyyaw;
  std::vector<double> spreads;
  std::vector<Iso3> poses;  // hand poses the top grasps reached
  std::vector<ApproachSpec> approaches;
  std::vector<int> on_object;  // the approaches that reach the object
};
int g_grasps = 256;
std::string g_mesh;

/// Seeded random approaches: direction -u, u uniform on the upper unit hemisphere; roll in
/// [-pi, pi); target within 1 cm of the centre of the mesh's bounding box.
std::vector<ApproachSpec> random_approaches(const TriMesh& mesh, int n) {
  const Vec3 centre = 0.5 * (mesh.V.colwise().minCoeff() + mesh.V.colwise().maxCoeff()).transpose();
  std::mt19937 rng(2);
  std::normal_distribution<double> N;
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::vector<ApproachSpec> out(n);
  for (ApproachSpec& a : out) {
    Vec3 u(N(rng), N(rng), N(rng));
    u.z() = std::abs(u.z());
    a.direction = -u.normalized();
    a.roll = M_PI * U(rng);
    a.target = centre + 0.01 * Vec3(U(rng), U(rng), U(rng));
  }
  return out;
}

Setup& setup() {
  static Setup s = [] {
    Setup s{HandModel::from_file(kSrc + "/python/bayesgrasp/data/hands/barrett_bh8.json"), {}, {}, {}, {}, {}};
    const std::string obj = g_mesh.empty() ? kSrc + "/bench/data/mug.obj" : g_mesh;
    if (!g_mesh.empty() && !std::ifstream(obj).good()) throw std::runtime_error("--mesh: cannot read " + obj);
    if (std::ifstream(obj).good()) {
      s.mug = read_obj(obj);
      s.mug_source = obj;
    } else {
      s.mug = generated_mug();
      s.mug_source = "generated (cylinder body + torus handle)";
    }
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> U(-1.0, 1.0), S(0.0, M_PI);
    s.xyyaw.resize(g_grasps, 3);
    for (int i = 0; i < g_grasps; ++i) {
      s.xyyaw.row(i) << 0.01 + 0.05 * U(rng), 0.05 * U(rng), M_PI * U(rng);
      s.spreads.push_back(S(rng));
    }
    const GraspSimulator sim(s.hand, s.mug);
    for (int i = 0; i < g_grasps; ++i)
      s.poses.push_back(sim.top_grasp(s.xyyaw(i, 0), s.xyyaw(i, 1), s.xyyaw(i, 2), s.spreads[i]).hand_pose);
    s.approaches = random_approaches(s.mug, g_grasps);
    for (int i = 0; i < g_grasps; ++i)
      if (!sim.approach(s.approaches[i], s.spreads[i]).stopped_by_table) s.on_object.push_back(i);
    return s;
  }();
  return s;
}

SimOptions variant(int v) {
  SimOptions o;
  switch (v) {
    case 1: o.bv = SimOptions::Bv::RSS; break;
    case 2: o.links = SimOptions::LinkGeometry::Primitives; break;
    case 3: o.links = SimOptions::LinkGeometry::Primitives, o.bv = SimOptions::Bv::RSS; break;
    case 4: o.rel_err = 0.25; break;
    case 5: o.box_skip = 1e9; break;
    case 6: o.links = SimOptions::LinkGeometry::Meshes; break;
    default: break;
  }
  return o;
}
const char* variant_name(int v) {
  static const char* names[] = {"OBBRSS+segments(default)", "RSS+segments", "OBBRSS+primitives",
                                "RSS+primitives", "error_allowance(rel_err=0.25)", "no_box_culling",
                                "OBBRSS+tessellated_capsules"};
  return names[v];
}

// Runs grasp(i) for every i of `which` (default: every grasp of the set) per iteration;
// counts grasps/s (CPU time), FCL queries, advancement steps and table stops per grasp.
template <class Grasp>
void run_grasps(benchmark::State& state, Grasp grasp, const std::vector<int>* which = nullptr) {
  int64_t n = 0, queries = 0, iterations = 0, table_stops = 0;
  const int count = which ? static_cast<int>(which->size()) : g_grasps;
  for (auto _ : state) {
    for (int k = 0; k < count; ++k) {
      const GraspResult r = grasp(which ? (*which)[k] : k);
      queries += r.distance_queries;
      iterations += r.iterations;
      table_stops += r.stopped_by_table;
      benchmark::DoNotOptimize(r.joints.data());
    }
    n += count;
  }
  state.SetItemsProcessed(n);
  state.counters["grasps_per_s"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsRate);
  state.counters["queries_per_grasp"] = static_cast<double>(queries) / n;
  state.counters["steps_per_grasp"] = static_cast<double>(iterations) / n;
  state.counters["table_stops"] = static_cast<double>(table_stops) / n;
}

void BM_TopGrasp(benchmark::State& state) {
  Setup& s = setup();
  const int v = static_cast<int>(state.range(0));
  const GraspSimulator sim(s.hand, s.mug, variant(v));
  state.SetLabel(variant_name(v));
  run_grasps(state, [&](int i) { return sim.top_grasp(s.xyyaw(i, 0), s.xyyaw(i, 1), s.xyyaw(i, 2), s.spreads[i]); });
}
BENCHMARK(BM_TopGrasp)->DenseRange(0, 5)->Unit(benchmark::kMillisecond);

// Approach/0: every approach; Approach/1: those that reach the object.
void BM_Approach(benchmark::State& state) {
  Setup& s = setup();
  const GraspSimulator sim(s.hand, s.mug);
  const bool on_object = state.range(0) == 1;
  state.SetLabel(on_object ? "reaching the object" : "all");
  run_grasps(state, [&](int i) { return sim.approach(s.approaches[i], s.spreads[i]); },
             on_object ? &s.on_object : nullptr);
}
BENCHMARK(BM_Approach)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_Close(benchmark::State& state) {
  Setup& s = setup();
  const GraspSimulator sim(s.hand, s.mug);
  run_grasps(state, [&](int i) { return sim.close(s.poses[i], s.spreads[i]); });
}
BENCHMARK(BM_Close)->Unit(benchmark::kMillisecond);

void BM_CloseFixedStep(benchmark::State& state) {
  Setup& s = setup();
  const GraspSimulator sim(s.hand, s.mug);
  run_grasps(state, [&](int i) { return sim.close_fixed_step(s.poses[i], s.spreads[i], 0.01); });
}
BENCHMARK(BM_CloseFixedStep)->Unit(benchmark::kMillisecond);

void BM_TopGraspBatch(benchmark::State& state) {
  Setup& s = setup();
  const GraspSimulator sim(s.hand, s.mug);
  const int threads = static_cast<int>(state.range(0));
  int64_t n = 0;
  for (auto _ : state) {
    const GraspBatch b = sim.top_grasp_batch(s.xyyaw, 1.0, 0.0, threads);
    benchmark::DoNotOptimize(b.joints.data());
    n += g_grasps;
  }
  state.counters["grasps_per_s"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TopGraspBatch)->Arg(1)->Arg(2)->ArgName("threads")->Unit(benchmark::kMillisecond)->UseRealTime();

void export_data(const std::string& dir) {
  Setup& s = setup();
  write_obj(s.mug, dir + "/mug.obj");
  const GraspSimulator sim(s.hand, s.mug);
  std::ofstream csv(dir + "/sim_grasps.csv");
  csv.precision(12);
  csv << "# hand pose (16, row-major), spread, our joints (J), fixed-step joints (J)\n";
  std::vector<double> diffs;
  double queries = 0, contacts = 0, collisions = 0;
  for (int i = 0; i < g_grasps; ++i) {
    const GraspResult a = sim.close(s.poses[i], s.spreads[i]);
    const GraspResult b = sim.close_fixed_step(s.poses[i], s.spreads[i], 0.01);
    const GraspResult t = sim.top_grasp(s.xyyaw(i, 0), s.xyyaw(i, 1), s.xyyaw(i, 2), s.spreads[i]);
    queries += t.distance_queries;
    contacts += static_cast<double>(t.contacts.size());
    collisions += t.collision_at_start;
    const Eigen::Matrix4d M = s.poses[i].matrix();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) csv << M(r, c) << ",";
    csv << s.spreads[i];
    for (int k = 0; k < a.joints.size(); ++k) csv << "," << a.joints[k];
    for (int k = 0; k < b.joints.size(); ++k) csv << "," << b.joints[k];
    csv << "\n";
    for (int k = 1; k < a.joints.size(); ++k) diffs.push_back(std::abs(a.joints[k] - b.joints[k]) * 180 / M_PI);
  }
  std::sort(diffs.begin(), diffs.end());
  const auto q = [&](double p) { return diffs[static_cast<size_t>(p * (diffs.size() - 1))]; };
  size_t within = 0;
  for (double d : diffs) within += d < 0.5;
  std::ofstream js(dir + "/sim_agreement.json");
  js << "{\"mug\": \"" << s.mug_source << "\", \"triangles\": " << s.mug.F.rows() << ", \"grasps\": " << g_grasps
     << ", \"finger_joint_diff_deg\": {\"median\": " << q(0.5) << ", \"p90\": " << q(0.9) << ", \"p99\": " << q(0.99)
     << ", \"max\": " << diffs.back() << ", \"fraction_below_0.5\": " << static_cast<double>(within) / diffs.size()
     << "}, \"top_grasp_queries_per_grasp\": " << queries / g_grasps
     << ", \"contacts_per_grasp\": " << contacts / g_grasps << ", \"collision_at_start\": " << collisions << "}\n";
  std::cout << "mug: " << s.mug_source << ", " << s.mug.F.rows() << " triangles; " << g_grasps << " grasps\n"
            << "finger joints, CA vs fixed 0.01-rad steps: median |diff| " << q(0.5) << " deg, p90 " << q(0.9)
            << ", max " << diffs.back() << "; " << 100.0 * within / diffs.size() << "% within 0.5 deg\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest;
  std::string export_dir;
  for (int i = 0; i < argc; ++i) {
    if (std::strncmp(argv[i], "--grasps=", 9) == 0) g_grasps = std::max(1, std::atoi(argv[i] + 9));
    else if (std::strncmp(argv[i], "--export=", 9) == 0) export_dir = argv[i] + 9;
    else if (std::strncmp(argv[i], "--mesh=", 7) == 0) g_mesh = argv[i] + 7;
    else rest.push_back(argv[i]);
  }
  int n = static_cast<int>(rest.size());
  if (!export_dir.empty()) export_data(export_dir);
  benchmark::Initialize(&n, rest.data());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

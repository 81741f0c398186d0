// Lift tests per second on one core (Bullet, default options: 1/480 s steps, 1.15 s script).
//  * BoxHeld:  an 8 x 5 x 12 cm box (hull shape) held by three fingertips - full script.
//  * BoxOpen:  the same box, open hand - the box stays on the table, early exit.
//  * CupHeld:  a concave cup (outer radius 4 cm, wall 4 mm, 10 cm tall, 64 segments,
//              512 triangles) held on its outer wall - full script; with the Auto shape
//              (fingers outside the hull -> hull), forced Tetrahedra and forced
//              Decomposition (17 convex pieces derived by hand: 16 wall sectors + floor).
//  * PotPinch: a pot (outer radius 6 cm, 4 mm wall, 12 cm tall, 512 triangles) whose wall is
//              pinched by finger 3 inside (through the opening) and fingers 1, 2 outside -
//              the case that needs a concave shape: Tetrahedra, and Auto with the
//              17-piece decomposition (Auto picks it, finger 3 is inside the hull).
// Each iteration is one LiftTester::run (its own Bullet world: set-up + simulation); the
// per-object preprocessing (mass properties, hull / tetrahedra) is done once, outside.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "../tests/cpp/physics_fixtures.hpp"
#include "bayesgrasp/physics/lift_test.hpp"

using namespace bayesgrasp;
using namespace bayesgrasp::fixtures;

namespace {

// Closes every finger in turn (from `start`, default open) until it touches the object.
template <class Dist>
Eigen::VectorXd touch(const HandModel& hand, const Iso3& T, Dist dist, Eigen::VectorXd start = {}) {
  Eigen::VectorXd t = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(hand.fingers().size()));
  if (start.size() == 0) start = t;
  for (int f = 0; f < static_cast<int>(hand.fingers().size()); ++f) t[f] = touch_actuator(hand, T, t, f, start[f], dist);
  return hand.coupled_joints(0.0, t);
}

void run_bench(benchmark::State& state, const LiftTester& tester, const Iso3& pose, const Eigen::VectorXd& q) {
  int lifted = 0, n = 0;
  double disp = 0;
  for (auto _ : state) {
    const LiftResult r = tester.run(pose, q);
    benchmark::DoNotOptimize(r);
    lifted += r.lifted;
    disp = r.displacement;
    ++n;
  }
  state.counters["lifted_fraction"] = static_cast<double>(lifted) / n;
  state.counters["displacement_m"] = disp;
  state.SetItemsProcessed(n);
}

const Vec3 kLo(-0.04, -0.025, 0.0), kHi(0.04, 0.025, 0.12);

double box_dist(const Vec3& p) { return (p - p.cwiseMax(kLo).cwiseMin(kHi)).norm(); }

// The box with the palm 1 cm above it; `held`: the fingertips touch it, else the hand is open.
void box_bench(benchmark::State& state, bool held) {
  const HandModel hand = barrett();
  const Iso3 pose = HandModel::top_grasp_pose(0, 0, 0, 0.13);
  LiftOptions o;
  o.density = 400.0;
  const LiftTester tester(hand, box_mesh(kLo, kHi), o);
  run_bench(state, tester, pose, held ? touch(hand, pose, box_dist) : hand.coupled_joints(0.0, 0.0));
}

void BM_LiftBoxHeld(benchmark::State& state) { box_bench(state, true); }
void BM_LiftBoxOpen(benchmark::State& state) { box_bench(state, false); }

void cup_bench(benchmark::State& state, LiftOptions::Shape shape) {
  const HandModel hand = barrett();
  const TriMesh cup = cup_mesh(0.04, 0.036, 0.10, 0.008, 64);
  const Iso3 pose = HandModel::top_grasp_pose(0, 0, 0, 0.115);  // 1.5 cm above the rim
  LiftOptions o;
  o.density = 1000.0;
  o.shape = shape;
  const LiftTester tester(hand, cup, o, cup_pieces(0.04, 0.036, 0.10, 0.008, 64, 4, Vec3::Zero()));
  // Distance to the outer wall (the fingers close on it from outside).
  auto cup_dist = [](const Vec3& p) {
    const double rr = std::hypot(p.x(), p.y());
    const double dz = p.z() > 0.10 ? p.z() - 0.10 : (p.z() < 0 ? -p.z() : 0.0);
    return std::hypot(std::max(0.0, rr - 0.04), dz);
  };
  state.counters["triangles"] = static_cast<double>(cup.F.rows());
  state.counters["tetrahedra"] = tester.run(pose, touch(hand, pose, cup_dist)).tetrahedra;
  run_bench(state, tester, pose, touch(hand, pose, cup_dist));
}

// The pot of tests/cpp/test_physics.cpp (PhysicsLiftConcave), centre 5.8 cm along +y.
void pot_bench(benchmark::State& state, LiftOptions::Shape shape, bool pieces) {
  const HandModel hand = barrett();
  const double R = 0.06, r = 0.056, h = 0.12, t = 0.008;
  const Vec3 c(0.0, 0.058, 0.0);
  const TriMesh pot = cup_mesh(R, r, h, t, 64, c);
  const Iso3 pose = HandModel::top_grasp_pose(0, 0, 0, h + 0.015);
  LiftOptions o;
  o.density = 100.0;
  o.shape = shape;
  const LiftTester tester(hand, pot, o,
                          pieces ? cup_pieces(R, r, h, t, 64, 4, c) : std::vector<Eigen::MatrixX3d>{});
  auto pot_dist = [&](const Vec3& p) { return cup_distance(p, R, r, h, t, c); };
  // Finger 3 from 60 deg (hanging inside the pot) to the inner wall, then fingers 1, 2.
  Eigen::VectorXd start = Eigen::VectorXd::Zero(3);
  start[2] = M_PI / 3;
  Eigen::VectorXd q = touch(hand, pose, pot_dist, start);
  const LiftResult r0 = tester.run(pose, q);
  state.counters["tetrahedra"] = r0.tetrahedra;
  state.counters["decomposition"] = r0.shape == LiftOptions::Shape::Decomposition;
  state.counters["height_gain_m"] = r0.height_gain;
  run_bench(state, tester, pose, q);
}

}  // namespace

void BM_LiftCupHeldDecomposition(benchmark::State& state) { cup_bench(state, LiftOptions::Shape::Decomposition); }
void BM_LiftPotPinchTetrahedra(benchmark::State& state) { pot_bench(state, LiftOptions::Shape::Tetrahedra, false); }
void BM_LiftPotPinchDecomposition(benchmark::State& state) { pot_bench(state, LiftOptions::Shape::Auto, true); }

void BM_LiftCupHeldTetrahedra(benchmark::State& state) { cup_bench(state, LiftOptions::Shape::Tetrahedra); }
// Auto: the fingers stay outside the cup's hull, so the hull is used.
void BM_LiftCupHeldAuto(benchmark::State& state) { cup_bench(state, LiftOptions::Shape::Auto); }

BENCHMARK(BM_LiftBoxHeld)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_LiftBoxOpen)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_LiftCupHeldAuto)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_LiftCupHeldTetrahedra)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_LiftCupHeldDecomposition)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_LiftPotPinchTetrahedra)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_LiftPotPinchDecomposition)->Unit(benchmark::kMillisecond)->MinTime(2.0);

BENCHMARK_MAIN();

// Lift tests per second on one core (Bullet, default options: 1/720 s steps, 1.15 s script).
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

#include "bayesgrasp/physics/lift_test.hpp"

using namespace bayesgrasp;

namespace {

HandModel barrett() {
  return HandModel::from_file(std::string(BAYESGRASP_SOURCE_DIR) + "/python/bayesgrasp/data/hands/barrett_bh8.json");
}

TriMesh box_mesh(const Vec3& lo, const Vec3& hi) {
  TriMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    m.V.row(i) << ((i & 1) ? hi.x() : lo.x()), ((i & 2) ? hi.y() : lo.y()), ((i & 4) ? hi.z() : lo.z());
  m.F.resize(12, 3);
  m.F << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5;
  return m;
}

// Closed cup: outer wall radius R, inner r, height h, floor thickness t, n segments.
TriMesh cup_mesh(double R, double r, double h, double t, int n) {
  // Rings: 0 outer bottom (z=0), 1 outer top (z=h), 2 inner top (z=h), 3 inner bottom (z=t);
  // centres: outer bottom centre, inner floor centre.
  TriMesh m;
  m.V.resize(4 * n + 2, 3);
  const double rad[4] = {R, R, r, r}, z[4] = {0, h, h, t};
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      m.V.row(k * n + i) << rad[k] * std::cos(a), rad[k] * std::sin(a), z[k];
    }
  const int cb = 4 * n, cf = 4 * n + 1;
  m.V.row(cb) << 0, 0, 0;
  m.V.row(cf) << 0, 0, t;
  std::vector<Eigen::Vector3i> f;
  auto quad = [&](int a, int b, int c, int d) {  // a b c d counter-clockwise from outside
    f.emplace_back(a, b, c);
    f.emplace_back(a, c, d);
  };
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    quad(0 * n + i, 0 * n + j, 1 * n + j, 1 * n + i);  // outer wall, normal outwards
    quad(1 * n + i, 1 * n + j, 2 * n + j, 2 * n + i);  // rim, normal up
    quad(2 * n + i, 2 * n + j, 3 * n + j, 3 * n + i);  // inner wall, normal inwards
    f.emplace_back(cf, 3 * n + j, 3 * n + i);          // inner floor, normal up
    f.emplace_back(cb, 0 * n + i, 0 * n + j);          // bottom, normal down
  }
  m.F.resize(static_cast<Eigen::Index>(f.size()), 3);
  for (size_t i = 0; i < f.size(); ++i) m.F.row(static_cast<Eigen::Index>(i)) = f[i].transpose();
  return m;
}

// Hand-made convex decomposition of cup_mesh(R, r, h, t, n) centred at c: n / per wall
// sectors (hull of their outer and inner ring points at z = 0 and h) and the floor.
std::vector<Eigen::MatrixX3d> cup_pieces(double R, double r, double h, double t, int n, int per, const Vec3& c) {
  std::vector<Eigen::MatrixX3d> out;
  auto pt = [&](double rad, int i, double z) {
    const double a = 2 * M_PI * i / n;
    return Eigen::RowVector3d(c.x() + rad * std::cos(a), c.y() + rad * std::sin(a), z);
  };
  for (int s = 0; s < n / per; ++s) {
    Eigen::MatrixX3d P(4 * (per + 1), 3);
    int k = 0;
    for (int i = s * per; i <= (s + 1) * per; ++i)
      for (double rad : {R, r})
        for (double z : {0.0, h}) P.row(k++) = pt(rad, i % n, z);
    out.push_back(P);
  }
  Eigen::MatrixX3d floor(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    floor.row(i) = pt(R, i, 0.0);
    floor.row(n + i) = pt(r, i, t);
  }
  out.push_back(floor);
  return out;
}

// Closes the fingers (coupled law) until each is within 0.1 mm of `dist` (a signed distance
// of a point to the object): scan, then bisect. Capsules sampled densely.
template <class Dist>
Eigen::VectorXd touch(const HandModel& hand, const Iso3& T, Dist dist, Eigen::VectorXd start = {}) {
  Eigen::VectorXd t = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(hand.fingers().size()));
  if (start.size() == 0) start = t;
  for (int f = 0; f < static_cast<int>(hand.fingers().size()); ++f) {
    auto d = [&](double tf) {
      Eigen::VectorXd tt = t;
      tt[f] = tf;
      const auto poses = hand.link_poses(T, hand.coupled_joints(0.0, tt));
      double best = 1e9;
      for (const Phalanx& ph : hand.fingers()[f].phalanges)
        for (const Shape& s : ph.shapes)
          for (int k = 0; k <= 200; ++k)
            best = std::min(best, dist(Vec3(poses[ph.link] * (s.p0 + (s.p1 - s.p0) * (k / 200.0)))) - s.radius);
      return best;
    };
    double a = start[f], b = start[f];
    while (b < hand.fingers()[f].t_max() && d(b) > 0) {
      a = b;
      b += 0.01;
    }
    for (int i = 0; i < 40; ++i) {
      const double m = 0.5 * (a + b);
      (d(m) > 1e-4 ? a : b) = m;
    }
    t[f] = a;
  }
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

void BM_LiftBoxHeld(benchmark::State& state) {
  const HandModel hand = barrett();
  const Iso3 pose = HandModel::top_grasp_pose(0, 0, 0, 0.13);
  LiftOptions o;
  o.density = 400.0;
  const LiftTester tester(hand, box_mesh(kLo, kHi), o);
  run_bench(state, tester, pose, touch(hand, pose, box_dist));
}

void BM_LiftBoxOpen(benchmark::State& state) {
  const HandModel hand = barrett();
  const Iso3 pose = HandModel::top_grasp_pose(0, 0, 0, 0.13);
  LiftOptions o;
  o.density = 400.0;
  const LiftTester tester(hand, box_mesh(kLo, kHi), o);
  run_bench(state, tester, pose, hand.coupled_joints(0.0, 0.0));
}

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
  // cup_mesh is centred at the origin: shift it.
  TriMesh pot = cup_mesh(R, r, h, t, 64);
  pot.V.rowwise() += c.transpose();
  const Iso3 pose = HandModel::top_grasp_pose(0, 0, 0, h + 0.015);
  LiftOptions o;
  o.density = 100.0;
  o.shape = shape;
  const LiftTester tester(hand, pot, o,
                          pieces ? cup_pieces(R, r, h, t, 64, 4, c) : std::vector<Eigen::MatrixX3d>{});
  auto pot_dist = [&](const Vec3& p) {  // signed distance to the wall or the floor (rho, z)
    const double rho = std::hypot(p.x() - c.x(), p.y() - c.y());
    auto rect = [&](double r0, double r1, double z0, double z1) {
      const double dx = std::max({r0 - rho, rho - r1, 0.0}), dz = std::max({z0 - p.z(), p.z() - z1, 0.0});
      if (dx == 0 && dz == 0) return -std::min({rho - r0, r1 - rho, p.z() - z0, z1 - p.z()});
      return std::hypot(dx, dz);
    };
    return std::min(rect(r, R, 0, h), rect(0, R, 0, t));
  };
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

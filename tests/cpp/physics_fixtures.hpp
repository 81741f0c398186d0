// Shared by tests/cpp/test_physics.cpp, tests/cpp/test_sim_approach.cpp and bench/bench_physics.cpp: the Barrett hand, a box
// and a cup (or pot) as closed meshes, the cup's hand-made convex decomposition and signed
// distance, and closing a finger until it touches an object given by its signed distance.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bayesgrasp/geometry/mesh.hpp"
#include "bayesgrasp/hand/hand_model.hpp"

namespace bayesgrasp::fixtures {

inline HandModel barrett() {
  return HandModel::from_file(std::string(BAYESGRASP_SOURCE_DIR) + "/python/bayesgrasp/data/hands/barrett_bh8.json");
}

// Axis-aligned box [lo, hi] as a closed, outward-wound triangle mesh.
inline TriMesh box_mesh(const Vec3& lo, const Vec3& hi) {
  TriMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    m.V.row(i) << ((i & 1) ? hi.x() : lo.x()), ((i & 2) ? hi.y() : lo.y()), ((i & 4) ? hi.z() : lo.z());
  m.F.resize(12, 3);
  m.F << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5;
  return m;
}

// Closed cup with a floor: outer radius R, inner r, height h, floor thickness t, n segments
// (outer wall, rim, inner wall, inner floor, bottom; 8n triangles).
inline TriMesh cup_mesh(double R, double r, double h, double t, int n, const Vec3& c = Vec3::Zero()) {
  TriMesh m;
  m.V.resize(4 * n + 2, 3);
  const double rad[4] = {R, R, r, r}, z[4] = {0, h, h, t};
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      m.V.row(k * n + i) << c.x() + rad[k] * std::cos(a), c.y() + rad[k] * std::sin(a), z[k];
    }
  const int cb = 4 * n, cf = 4 * n + 1;
  m.V.row(cb) << c.x(), c.y(), 0;
  m.V.row(cf) << c.x(), c.y(), t;
  std::vector<Eigen::Vector3i> f;
  auto quad = [&](int a, int b, int cc, int d) {
    f.emplace_back(a, b, cc);
    f.emplace_back(a, cc, d);
  };
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    quad(0 * n + i, 0 * n + j, 1 * n + j, 1 * n + i);
    quad(1 * n + i, 1 * n + j, 2 * n + j, 2 * n + i);
    quad(2 * n + i, 2 * n + j, 3 * n + j, 3 * n + i);
    f.emplace_back(cf, 3 * n + j, 3 * n + i);
    f.emplace_back(cb, 0 * n + i, 0 * n + j);
  }
  m.F.resize(static_cast<Eigen::Index>(f.size()), 3);
  for (size_t i = 0; i < f.size(); ++i) m.F.row(static_cast<Eigen::Index>(i)) = f[i].transpose();
  return m;
}

// A convex decomposition of that cup derived by hand: the wall cut into n / per sectors
// (each the hull of its outer and inner ring points, top and bottom; its inner face is a
// chord, at most r (1 - cos(pi per / n)) into the cavity), and the floor (hull of the
// outer bottom ring and the inner floor ring, inside the solid).
inline std::vector<Eigen::MatrixX3d> cup_pieces(double R, double r, double h, double t, int n, int per, const Vec3& c) {
  std::vector<Eigen::MatrixX3d> out;
  auto ring_point = [&](double rad, int i, double z) {
    const double a = 2 * M_PI * i / n;
    return Eigen::RowVector3d(c.x() + rad * std::cos(a), c.y() + rad * std::sin(a), z);
  };
  for (int s = 0; s < n / per; ++s) {
    Eigen::MatrixX3d P(4 * (per + 1), 3);
    int k = 0;
    for (int i = s * per; i <= (s + 1) * per; ++i)
      for (double rad : {R, r})
        for (double z : {0.0, h}) P.row(k++) = ring_point(rad, i % n, z);
    out.push_back(P);
  }
  Eigen::MatrixX3d floor(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    floor.row(i) = ring_point(R, i, 0.0);
    floor.row(n + i) = ring_point(r, i, t);
  }
  out.push_back(floor);
  return out;
}

// Signed distance (outside > 0) of a point to that cup's solid: in the (rho, z) half-plane
// the solid is the union of the wall [r, R] x [0, h] and the floor [0, R] x [0, t].
inline double cup_distance(const Vec3& p, double R, double r, double h, double t, const Vec3& c) {
  const double rho = std::hypot(p.x() - c.x(), p.y() - c.y());
  auto rect = [&](double r0, double r1, double z0, double z1) {
    const double dx = std::max({r0 - rho, rho - r1, 0.0}), dz = std::max({z0 - p.z(), p.z() - z1, 0.0});
    if (dx == 0 && dz == 0) return -std::min({rho - r0, r1 - rho, p.z() - z0, z1 - p.z()});
    return std::hypot(dx, dz);
  };
  return std::min(rect(r, R, 0, h), rect(0, R, 0, t));
}

// Closes finger f from actuator value t0 until it is within 0.1 mm of the object (signed
// distance `dist`; its capsules' axes sampled at `samples` + 1 points): scan in 0.01 rad steps,
// then bisect. Returns the actuator value; `start_gap` / `end_gap` (if given) receive the
// finger's distance at t0 and at the result.
template <class Dist>
double touch_actuator(const HandModel& hand, const Iso3& T, Eigen::VectorXd t, int f, double t0, Dist dist,
                      double* start_gap = nullptr, double* end_gap = nullptr, int samples = 400) {
  auto d = [&](double tf) {
    t[f] = tf;
    const auto poses = hand.link_poses(T, hand.coupled_joints(0.0, t));
    double best = 1e9;
    for (const Phalanx& ph : hand.fingers()[f].phalanges)
      for (const Shape& s : ph.shapes) {
        if (s.type != Shape::Type::Capsule) continue;
        for (int k = 0; k <= samples; ++k)
          best = std::min(best, dist(Vec3(poses[ph.link] * (s.p0 + (s.p1 - s.p0) * (double(k) / samples)))) - s.radius);
      }
    return best;
  };
  if (start_gap) *start_gap = d(t0);
  double a = t0, b = t0;
  while (b < hand.fingers()[f].t_max() && d(b) > 0) {
    a = b;
    b += 0.01;
  }
  for (int i = 0; i < 40; ++i) {
    const double m = 0.5 * (a + b);
    (d(m) > 1e-4 ? a : b) = m;
  }
  if (end_gap) *end_gap = d(a);
  return a;
}

}  // namespace bayesgrasp::fixtures

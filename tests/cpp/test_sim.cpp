// Contact simulation against angles derived by hand (planar trigonometry in a finger's plane).
//
// Barrett finger in its own plane: u = outward distance from the hand axis, w = depth below the
// palm face (along the approach direction). The proximal joint is at (u0, 0) (u0 = 75 mm for
// fingers 1 and 2, 50 mm for finger 3); at proximal angle th the proximal capsule is the
// segment (u0, 0) + s (cos th, sin th), s in [0, 70 mm], radius 12.5 mm; the distal capsule is
// the segment from the distal joint (u0 + 70 cos th, 70 sin th) along angle
// phi = th + th/3 + 42 deg, length 45 mm, radius 10 mm.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "bayesgrasp/sim/grasp_simulator.hpp"

using namespace bayesgrasp;

namespace {
const std::string kBarrett = std::string(BAYESGRASP_SOURCE_DIR) + "/python/bayesgrasp/data/hands/barrett_bh8.json";
const std::string kRobotiq = std::string(BAYESGRASP_SOURCE_DIR) + "/python/bayesgrasp/data/hands/robotiq_3f.json";
constexpr double kDeg = M_PI / 180.0;

/// Closed vertical cylinder, axis z from z0 to z1, n sides with a vertex at angle 0.
TriMesh cylinder(double r, double z0, double z1, int n, double cx = 0, double cy = 0) {
  TriMesh m;
  m.V.resize(2 * n + 2, 3);
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    m.V.row(i) << cx + r * std::cos(a), cy + r * std::sin(a), z0;
    m.V.row(n + i) << cx + r * std::cos(a), cy + r * std::sin(a), z1;
  }
  m.V.row(2 * n) << cx, cy, z0;
  m.V.row(2 * n + 1) << cx, cy, z1;
  m.F.resize(4 * n, 3);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.F.row(4 * i) << i, j, n + j;
    m.F.row(4 * i + 1) << i, n + j, n + i;
    m.F.row(4 * i + 2) << 2 * n, j, i;
    m.F.row(4 * i + 3) << 2 * n + 1, n + i, n + j;
  }
  return m;
}

/// UV sphere with poles on z.
TriMesh sphere(const Vec3& c, double r, int nu, int nv) {
  TriMesh m;
  const int rings = nv - 1;
  m.V.resize(2 + rings * nu, 3);
  m.V.row(0) = (c + Vec3(0, 0, -r)).transpose();
  for (int k = 0; k < rings; ++k) {
    const double phi = -M_PI / 2 + M_PI * (k + 1) / nv;
    for (int i = 0; i < nu; ++i) {
      const double a = 2 * M_PI * i / nu;
      m.V.row(1 + k * nu + i) = (c + r * Vec3(std::cos(phi) * std::cos(a), std::cos(phi) * std::sin(a), std::sin(phi))).transpose();
    }
  }
  const int top = 1 + rings * nu;
  m.V.row(top) = (c + Vec3(0, 0, r)).transpose();
  std::vector<Eigen::Vector3i> f;
  for (int i = 0; i < nu; ++i) f.emplace_back(0, 1 + (i + 1) % nu, 1 + i);
  for (int k = 0; k + 1 < rings; ++k)
    for (int i = 0; i < nu; ++i) {
      const int a = 1 + k * nu + i, b = 1 + k * nu + (i + 1) % nu;
      f.emplace_back(a, b, b + nu);
      f.emplace_back(a, b + nu, a + nu);
    }
  const int last = 1 + (rings - 1) * nu;
  for (int i = 0; i < nu; ++i) f.emplace_back(top, last + i, last + (i + 1) % nu);
  m.F.resize(static_cast<int>(f.size()), 3);
  for (size_t i = 0; i < f.size(); ++i) m.F.row(static_cast<int>(i)) = f[i].transpose();
  return m;
}

TriMesh box_mesh(const Vec3& lo, const Vec3& hi) {
  TriMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    m.V.row(i) << (i & 1 ? hi.x() : lo.x()), (i & 2 ? hi.y() : lo.y()), (i & 4 ? hi.z() : lo.z());
  m.F.resize(12, 3);
  m.F << 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5;
  return m;
}

/// Smallest root of a increasing-crossing function on [a, b] by scanning then bisection.
double first_crossing(const std::function<double(double)>& g, double a, double b) {
  const int n = 2000;
  double prev = a;
  for (int i = 1; i <= n; ++i) {
    const double x = a + (b - a) * i / n;
    if (g(x) <= 0) {
      double lo = prev, hi = x;
      for (int k = 0; k < 60; ++k) {
        const double mid = 0.5 * (lo + hi);
        (g(mid) <= 0 ? hi : lo) = mid;
      }
      return 0.5 * (lo + hi);
    }
    prev = x;
  }
  return NAN;
}

struct Seg {
  double u0, w0, u1, w1;
};
Seg proximal_seg(double u0, double th) { return {u0, 0, u0 + 0.07 * std::cos(th), 0.07 * std::sin(th)}; }
Seg distal_seg(double u0, double th) {
  const double ju = u0 + 0.07 * std::cos(th), jw = 0.07 * std::sin(th);
  const double phi = th + th / 3 + 42 * kDeg;
  return {ju, jw, ju + 0.045 * std::cos(phi), jw + 0.045 * std::sin(phi)};
}
double point_seg_dist(double pu, double pw, const Seg& s) {
  const double du = s.u1 - s.u0, dw = s.w1 - s.w0;
  const double t = std::clamp(((pu - s.u0) * du + (pw - s.w0) * dw) / (du * du + dw * dw), 0.0, 1.0);
  return std::hypot(pu - s.u0 - t * du, pw - s.w0 - t * dw);
}

/// Distance from point p to triangle (a, b, c), by projection and edge clamping.
double point_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a).normalized();
  const Vec3 q = p - n.dot(p - a) * n;
  auto inside = [&](const Vec3& x, const Vec3& y) { return (y - x).cross(q - x).dot(n) >= 0; };
  if (inside(a, b) && inside(b, c) && inside(c, a)) return (p - q).norm();
  auto seg = [&](const Vec3& x, const Vec3& y) {
    const double t = std::clamp((p - x).dot(y - x) / (y - x).squaredNorm(), 0.0, 1.0);
    return (p - x - t * (y - x)).norm();
  };
  return std::min({seg(a, b), seg(b, c), seg(c, a)});
}
double point_mesh(const Vec3& p, const TriMesh& m) {
  double d = 1e9;
  for (int i = 0; i < m.F.rows(); ++i)
    d = std::min(d, point_triangle(p, m.V.row(m.F(i, 0)).transpose(), m.V.row(m.F(i, 1)).transpose(),
                                   m.V.row(m.F(i, 2)).transpose()));
  return d;
}

}  // namespace

// Vertical cylinder r = 35 mm, 200 mm tall, on the table; top grasp at its centre with spread
// 90 deg (fingers 1 and 2 opposite along the hand's x). The palm lands on the top face; then
// each finger closes until its distal capsule meets the cylinder's side: the innermost point of
// the distal segment reaches u = r + 10 mm (the polygon has vertices at 0 and 90 deg, so in the
// finger plane its extent is exactly r). The proximal would touch only later (u0 + 70 cos th
// = r + 12.5 mm), so the finger freezes whole at the distal contact.
TEST(Sim, TopGraspOnCylinderMatchesTrigonometry) {
  const HandModel hand = HandModel::from_file(kBarrett);
  const double r = 0.035, h = 0.2;  // r < 37.5 mm: finger 3's open proximal capsule clears the top
  const TriMesh cyl = cylinder(r, 0.0, h, 256);
  const GraspSimulator sim(hand, cyl);
  const GraspResult g = sim.top_grasp(0, 0, 0, 90 * kDeg);
  ASSERT_FALSE(g.collision_at_start);
  // palm on the top face
  EXPECT_NEAR(g.hand_pose.translation().z(), h, 2e-4);
  EXPECT_TRUE(g.link_contact[0]);
  auto expected = [&](double u0) {
    const double th_d = first_crossing([&](double th) {
      const Seg s = distal_seg(u0, th);
      return std::min(s.u0, s.u1) - (r + 0.010);
    }, 0.0, 140 * kDeg);
    const double th_p = first_crossing([&](double th) { return u0 + 0.07 * std::cos(th) - (r + 0.0125); }, 0.0, 140 * kDeg);
    EXPECT_LT(th_d, th_p);
    return th_d;
  };
  const double th12 = expected(0.075), th3 = expected(0.05);
  // sanity of the hand derivation: roughly 79 and 65 deg
  EXPECT_NEAR(th12 / kDeg, 81.5, 1.5);
  EXPECT_NEAR(th3 / kDeg, 67.0, 1.5);
  for (int f = 0; f < 3; ++f) {
    const double th = f < 2 ? th12 : th3;
    const int j = hand.fingers()[f].first_joint;
    EXPECT_NEAR(g.joints[j] / kDeg, th / kDeg, 0.5) << "finger " << f;
    EXPECT_NEAR(g.joints[j + 1] / kDeg, (th / 3 + 42 * kDeg) / kDeg, 0.5) << "finger " << f;
    EXPECT_TRUE(g.link_contact[hand.fingers()[f].phalanges[1].link]);
    EXPECT_FALSE(g.link_contact[hand.fingers()[f].phalanges[0].link]);
  }
  // palm, the two knuckle boxes (flush with the palm face) and the three distal links
  EXPECT_TRUE(g.link_contact[hand.fingers()[0].knuckle_link]);
  EXPECT_TRUE(g.link_contact[hand.fingers()[1].knuckle_link]);
  EXPECT_EQ(g.contacts.size(), 6u);
}

// Sphere R = 50 mm centred 50 mm below the palm face (top grasp onto a sphere resting on the
// table: the palm lands on its top). Contact when the distance from the sphere's centre
// (u = 0, w = R) to a capsule's segment equals R + radius.
TEST(Sim, TopGraspOnSphereMatchesTrigonometry) {
  const HandModel hand = HandModel::from_file(kBarrett);
  const double R = 0.05;
  const TriMesh sph = sphere(Vec3(0, 0, R), R, 256, 128);
  SimOptions opt;
  opt.table = false;
  const GraspSimulator sim(hand, sph, opt);
  const GraspResult g = sim.top_grasp(0, 0, 0, 90 * kDeg);
  ASSERT_FALSE(g.collision_at_start);
  EXPECT_NEAR(g.hand_pose.translation().z(), 2 * R, 2e-4);
  for (int f = 0; f < 3; ++f) {
    const double u0 = f < 2 ? 0.075 : 0.05;
    const double th_d = first_crossing([&](double th) { return point_seg_dist(0, R, distal_seg(u0, th)) - (R + 0.010); }, 0, 140 * kDeg);
    const double th_p = first_crossing([&](double th) { return point_seg_dist(0, R, proximal_seg(u0, th)) - (R + 0.0125); }, 0, 140 * kDeg);
    const int j = hand.fingers()[f].first_joint;
    if (th_d < th_p) {  // distal first: the whole finger stops
      EXPECT_NEAR(g.joints[j] / kDeg, th_d / kDeg, 0.5) << "finger " << f;
      EXPECT_NEAR(g.joints[j + 1] / kDeg, (th_d / 3 + 42 * kDeg) / kDeg, 0.5);
    } else {  // proximal first: it stops there
      EXPECT_NEAR(g.joints[j] / kDeg, th_p / kDeg, 0.5) << "finger " << f;
    }
  }
}

// Breakaway: a small sphere (radius 10 mm) just in front of finger 1's proximal link, tangent to
// its capsule when the proximal angle is 45 deg (centre at 30 mm along the link and 22.5 mm in
// front of its axis). The proximal stops at 45 deg; the distal, which never meets the sphere
// (its points stay more than 60 mm from the proximal joint), keeps closing to its 90 deg limit,
// far above the coupled value 45/3 + 42 = 57 deg.
TEST(Sim, BreakawayAfterProximalContact) {
  const HandModel hand = HandModel::from_file(kBarrett);
  const double thc = 45 * kDeg, u0 = 0.075;
  // finger 1 at spread 90 deg points along +x of the hand; hand frame = world (approach +z)
  const double cu = u0 + 0.03 * std::cos(thc) - 0.0225 * std::sin(thc);
  const double cw = 0.03 * std::sin(thc) + 0.0225 * std::cos(thc);
  const TriMesh ball = sphere(Vec3(cu, 0, cw), 0.01, 128, 64);
  SimOptions opt;
  opt.table = false;
  const GraspSimulator sim(hand, ball, opt);
  const GraspResult g = sim.close(Iso3::Identity(), 90 * kDeg);
  ASSERT_FALSE(g.collision_at_start);
  EXPECT_NEAR(g.joints[1] / kDeg, 45.0, 0.5);
  EXPECT_NEAR(g.joints[2] / kDeg, 90.0, 1e-9);
  EXPECT_GT(g.joints[2], g.joints[1] / 3 + 42 * kDeg + 30 * kDeg);
  EXPECT_TRUE(g.link_contact[hand.fingers()[0].phalanges[0].link]);
  // the other fingers close freely to their limits
  EXPECT_NEAR(g.joints[3] / kDeg, 140.0, 1e-9);
  EXPECT_NEAR(g.joints[4] / kDeg, 90.0, 1e-9);
}

// Table: palm down 80 mm above the table, object far away. The distal tip sphere (radius 10 mm)
// reaches the table when 70 sin th + 45 sin(4 th / 3 + 42 deg) + 10 mm = 80 mm.
TEST(Sim, TableStopsFinger) {
  const HandModel hand = HandModel::from_file(kBarrett);
  const TriMesh far_box = box_mesh(Vec3(1.0, 1.0, 0.0), Vec3(1.05, 1.05, 0.05));
  const GraspSimulator sim(hand, far_box);
  const GraspResult g = sim.close(HandModel::top_grasp_pose(0, 0, 0, 0.08), 90 * kDeg);
  ASSERT_FALSE(g.collision_at_start);
  const double th = first_crossing([&](double t) {
    const Seg s = distal_seg(0.075, t);
    return 0.07 - std::max(s.w0, s.w1);
  }, 0, 140 * kDeg);
  EXPECT_NEAR(th / kDeg, 23.5, 1.5);
  for (int f = 0; f < 3; ++f) {
    EXPECT_NEAR(g.joints[hand.fingers()[f].first_joint] / kDeg, th / kDeg, 0.5);
    EXPECT_TRUE(g.table_contact[hand.fingers()[f].phalanges[1].link]);
  }
  int on_table = 0;
  for (const Contact& c : g.contacts) {
    EXPECT_TRUE(c.on_table);
    EXPECT_NEAR(c.point.z(), 0.0, 1e-12);
    EXPECT_TRUE(c.normal.isApprox(Vec3::UnitZ()));
    on_table += c.on_table;
  }
  EXPECT_EQ(on_table, 3);
}

TEST(Sim, CollisionAtStart) {
  const HandModel hand = HandModel::from_file(kBarrett);
  const TriMesh cube = box_mesh(Vec3(-0.03, -0.03, 0.0), Vec3(0.03, 0.03, 0.06));
  const GraspSimulator sim(hand, cube);
  // palm face 10 mm below the cube's top: the palm box cuts the cube
  const GraspResult a = sim.close(HandModel::top_grasp_pose(0, 0, 0, 0.05), 0.0);
  EXPECT_TRUE(a.collision_at_start);
  EXPECT_TRUE(a.contacts.empty());
  EXPECT_TRUE(a.joints.isApprox(hand.coupled_joints(0.0, 0.0)));
  // a fingertip below the table
  const GraspResult b = sim.close(HandModel::top_grasp_pose(0.5, 0.5, 0, 0.01), 0.0);
  EXPECT_TRUE(b.collision_at_start);
  // the whole hand inside a big box (no surface crossing): still a collision
  const TriMesh big = box_mesh(Vec3(-1, -1, 0.1), Vec3(1, 1, 1));
  const GraspSimulator sim_big(hand, big);
  EXPECT_TRUE(sim_big.close(HandModel::top_grasp_pose(0, 0, 0, 0.5), 0.0).collision_at_start);
  // and well above the cube: free
  EXPECT_FALSE(sim.close(HandModel::top_grasp_pose(0, 0, 0, 0.3), 0.0).collision_at_start);
}

// Random top grasps on a cylinder: contacts lie on the surface, unit normals, links stop
// within the tolerance; batch = serial; same input, same output; GraspIt!-style stepping
// agrees.
TEST(Sim, ContactsOnSurfaceBatchAndDeterminism) {
  const HandModel hand = HandModel::from_file(kBarrett);
  const TriMesh cyl = cylinder(0.035, 0.0, 0.12, 48, 0.01, -0.005);
  const GraspSimulator sim(hand, cyl);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> xyyaw(24, 3);
  for (int i = 0; i < 24; ++i) xyyaw.row(i) << 0.04 * U(rng), 0.04 * U(rng), M_PI * U(rng);
  const double spread = 40 * kDeg;
  const GraspBatch b1 = sim.top_grasp_batch(xyyaw, spread, 0.0, 1);
  const GraspBatch b2 = sim.top_grasp_batch(xyyaw, spread, 0.0, 2);
  EXPECT_EQ(b1.joints, b2.joints);
  EXPECT_EQ(b1.offsets, b2.offsets);
  int object_contacts = 0, close_joints = 0, all_joints = 0;
  for (int i = 0; i < 24; ++i) {
    const GraspResult g = sim.top_grasp(xyyaw(i, 0), xyyaw(i, 1), xyyaw(i, 2), spread);
    EXPECT_EQ(g.joints.transpose(), b1.joints.row(i));
    ASSERT_EQ(static_cast<int64_t>(g.contacts.size()), b1.offsets[i + 1] - b1.offsets[i]);
    EXPECT_TRUE(g.hand_pose.isApprox(b1.hand_poses[i]));
    for (const Contact& c : g.contacts) {
      EXPECT_NEAR(c.normal.norm(), 1.0, 1e-9);
      EXPECT_GE(c.penetration, 0.0);
      if (!c.on_table) {
        ++object_contacts;
        EXPECT_LT(point_mesh(c.point, cyl), 3e-4);
        EXPECT_TRUE(g.link_contact[c.link]);
        // the link really is within the tolerance of the object
        EXPECT_LT(sim.link_object_distance(g.hand_pose, g.joints, c.link), 2e-4);
      }
    }
    // no link penetrates
    for (int l = 0; l < hand.num_links(); ++l)
      if (!hand.links()[l].shapes.empty()) EXPECT_GE(sim.link_object_distance(g.hand_pose, g.joints, l), 0.0);
    // GraspIt!-style stepping reaches the same angles (within its 0.01-rad step's bisection)
    const GraspResult s = sim.close_fixed_step(g.hand_pose, spread, 0.01);
    EXPECT_FALSE(s.collision_at_start);
    // (a link sliding along an edge stops where it starts to cut in, which is ill-conditioned
    // in angle: allow 2 deg there, and require most joints to agree to 0.5 deg)
    const Eigen::VectorXd diff = (s.joints - g.joints).cwiseAbs();
    EXPECT_LT(diff.maxCoeff(), 2.0 * kDeg) << "grasp " << i;
    for (int k = 0; k < diff.size(); ++k) close_joints += diff[k] < 0.5 * kDeg, all_joints += 1;
  }
  EXPECT_GT(object_contacts, 24);
  EXPECT_GT(close_joints, 0.85 * all_joints);
}

TEST(Sim, StandoffAndBadInput) {
  const HandModel hand = HandModel::from_file(kBarrett);
  const TriMesh cyl = cylinder(0.03, 0.0, 0.15, 64);
  const GraspSimulator sim(hand, cyl);
  const GraspResult a = sim.top_grasp(0, 0, 0, 0.0, 0.0);
  const GraspResult b = sim.top_grasp(0, 0, 0, 0.0, 0.01);
  EXPECT_NEAR(b.hand_pose.translation().z() - a.hand_pose.translation().z(), 0.01, 1e-12);
  EXPECT_FALSE(b.link_contact[0]);  // the palm no longer touches
  EXPECT_THROW(sim.top_grasp(0, 0, 0, -0.1), std::invalid_argument);
  EXPECT_THROW(sim.top_grasp(0, 0, 0, 4.0), std::invalid_argument);
  EXPECT_THROW(sim.top_grasp(NAN, 0, 0, 0.0), std::invalid_argument);
  EXPECT_THROW(sim.top_grasp(0, 0, 0, 0.0, -1.0), std::invalid_argument);
  Iso3 bad = Iso3::Identity();
  bad(0, 3) = NAN;
  EXPECT_THROW(sim.close(bad, 0.0), std::invalid_argument);
  EXPECT_THROW(sim.close_batch({Iso3::Identity(), Iso3::Identity()}, {0.0, 0.0, 0.0}, 1), std::invalid_argument);
  EXPECT_THROW(GraspSimulator(hand, TriMesh{}), std::invalid_argument);
}

// Options that change only the FCL representation give the same grasps.
TEST(Sim, RepresentationsAgree) {
  const HandModel hand = HandModel::from_file(kBarrett);
  // centred on a slim cylinder: every link meets the side head-on (no sliding contact,
  // whose end point is ill-conditioned)
  const TriMesh cyl = cylinder(0.03, 0.0, 0.2, 256);
  SimOptions rss;
  rss.bv = SimOptions::Bv::RSS;
  SimOptions exact;
  exact.rel_err = 0.0;
  exact.box_skip = 1e9;
  const GraspResult a = GraspSimulator(hand, cyl).top_grasp(0.002, 0, 0.3, 60 * kDeg);
  const GraspResult b = GraspSimulator(hand, cyl, rss).top_grasp(0.002, 0, 0.3, 60 * kDeg);
  const GraspResult c = GraspSimulator(hand, cyl, exact).top_grasp(0.002, 0, 0.3, 60 * kDeg);
  EXPECT_LT((a.joints - b.joints).cwiseAbs().maxCoeff(), 0.2 * kDeg);
  EXPECT_LT((a.joints - c.joints).cwiseAbs().maxCoeff(), 0.2 * kDeg);
}

// Query pruning skips FCL queries that cannot change the result: the same grasps as one query
// per link and step, with fewer queries.
TEST(Sim, QueryPruningKeepsTheResult) {
  const HandModel hand = HandModel::from_file(kBarrett);
  TriMesh scene = cylinder(0.035, 0.0, 0.11, 64, 0.005, -0.004);
  const TriMesh knob = sphere(Vec3(0.03, 0.02, 0.11), 0.02, 32, 16);  // an off-centre bump
  const int base = static_cast<int>(scene.V.rows());
  scene.V.conservativeResize(base + knob.V.rows(), 3);
  scene.V.bottomRows(knob.V.rows()) = knob.V;
  const int nf = static_cast<int>(scene.F.rows());
  scene.F.conservativeResize(nf + knob.F.rows(), 3);
  scene.F.bottomRows(knob.F.rows()) = knob.F.array() + base;
  SimOptions on, off;
  off.prune_queries = false;
  const GraspSimulator a(hand, scene, on), b(hand, scene, off);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  long qa = 0, qb = 0;
  for (int i = 0; i < 40; ++i) {
    const double x = 0.05 * U(rng), y = 0.05 * U(rng), yaw = M_PI * U(rng), spread = (0.5 + 0.5 * U(rng)) * M_PI / 2;
    const GraspResult ga = a.top_grasp(x, y, yaw, spread), gb = b.top_grasp(x, y, yaw, spread);
    EXPECT_LT((ga.joints - gb.joints).cwiseAbs().maxCoeff(), 1e-6) << "grasp " << i;
    EXPECT_LT((ga.hand_pose.translation() - gb.hand_pose.translation()).norm(), 1e-9) << "grasp " << i;
    EXPECT_EQ(ga.link_contact, gb.link_contact) << "grasp " << i;
    EXPECT_EQ(ga.contacts.size(), gb.contacts.size()) << "grasp " << i;
    qa += ga.distance_queries, qb += gb.distance_queries;
  }
  EXPECT_LT(qa, qb);
  // approaches from tilted directions (separating-plane bound, box queries capped first)
  int on_object = 0;
  for (int i = 0; i < 40; ++i) {
    const Vec3 d(0.8 * U(rng), 0.8 * U(rng), -1.0);
    const ApproachSpec s{d, M_PI * U(rng), Vec3(0.01 * U(rng), 0.01 * U(rng), 0.06 + 0.03 * U(rng))};
    const double spread = (0.5 + 0.5 * U(rng)) * M_PI / 2;
    const GraspResult ga = a.approach(s, spread), gb = b.approach(s, spread);
    EXPECT_LT((ga.joints - gb.joints).cwiseAbs().maxCoeff(), 1e-6) << "approach " << i;
    EXPECT_LT((ga.hand_pose.translation() - gb.hand_pose.translation()).norm(), 1e-9) << "approach " << i;
    EXPECT_EQ(ga.link_contact, gb.link_contact) << "approach " << i;
    EXPECT_EQ(ga.stopped_by_table, gb.stopped_by_table) << "approach " << i;
    on_object += !ga.stopped_by_table;
  }
  EXPECT_GT(on_object, 10);
}

// A palm resting on a cylinder's top face pushes along +z: its contact normal is the top face's,
// also when the nearest points lie on the rim (where the side wall's triangles meet the top).
TEST(Sim, PalmOnTopFaceHasAVerticalNormal) {
  const HandModel hand = HandModel::from_file(kBarrett);
  const TriMesh cyl = cylinder(0.035, 0.0, 0.2, 64);
  const GraspSimulator sim(hand, cyl);
  int palm_contacts = 0;
  for (double yaw : {0.0, 0.4, 1.1}) {
    const GraspResult g = sim.top_grasp(0.0, 0.0, yaw, 60 * kDeg);
    for (const Contact& c : g.contacts) {
      if (c.on_table || c.link != 0) continue;
      ++palm_contacts;
      EXPECT_NEAR(c.point.z(), 0.2, 3e-4);
      EXPECT_GT(c.normal.z(), 0.999) << "yaw " << yaw;
    }
  }
  EXPECT_GT(palm_contacts, 0);
}

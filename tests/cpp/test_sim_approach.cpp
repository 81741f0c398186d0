// Approaches (sim/approach.hpp, GraspSimulator::approach) along directions other than the top
// grasps' -z, against where the first contact must be: the open hand's support along a face's
// normal (the largest coordinate of its capsules and boxes, computed here from the hand file's
// shapes) within the contact tolerance of the face; the stand-off measured along the
// direction; the table stopping the hand; the top grasp as the approach along -z; bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "bayesgrasp/sim/approach.hpp"
#include "bayesgrasp/sim/grasp_simulator.hpp"
#include "bayesgrasp/sim/sim_scene.hpp"
#include "physics_fixtures.hpp"

using namespace bayesgrasp;
using fixtures::box_mesh;

namespace {

/// Hand pose whose approach axis (hand +z) is the world direction u, palm at p.
Iso3 facing(const Vec3& u, const Vec3& p) {
  Iso3 T = Iso3::Identity();
  T.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), u).toRotationMatrix();
  T.translation() = p;
  return T;
}

/// Largest coordinate along unit n of the hand's shapes at joints q and hand pose H.
double support(const HandModel& hand, const Iso3& H, const Eigen::VectorXd& q, const Vec3& n) {
  const std::vector<Iso3> poses = hand.link_poses(H, q);
  double best = -1e9;
  for (int l = 0; l < hand.num_links(); ++l)
    for (const Shape& sh : hand.links()[l].shapes) {
      const Mat3 R = poses[l].linear();
      if (sh.type == Shape::Type::Capsule)
        best = std::max(best, std::max(n.dot(poses[l] * sh.p0), n.dot(poses[l] * sh.p1)) + sh.radius);
      else
        best = std::max(best, n.dot(poses[l] * sh.center) + (R.transpose() * n).cwiseAbs().dot(sh.half_extents));
    }
  return best;
}

}  // namespace

TEST(SimApproach, SidewaysApproachStopsAtTheWall) {
  const HandModel hand = fixtures::barrett();
  // A wall x in [0, 0.2] standing on the table, far larger than the hand.
  const GraspSimulator sim(hand, box_mesh(Vec3(0.0, -0.4, 0.0), Vec3(0.2, 0.4, 0.8)));
  const sim::SimScene& s = sim.scene();
  const double tol = s.options.contact_tolerance;
  const Eigen::VectorXd open = hand.coupled_joints(hand.spread_default(), 0.0);
  for (const Vec3& u : {Vec3(1, 0, 0), Vec3(std::sqrt(0.5), std::sqrt(0.5), 0), Vec3(0.6, 0.0, -0.8)}) {
    const Iso3 start = facing(u, Vec3(-0.5, -0.5 * u.y() / u.x(), 0.4 - 0.5 * u.z() / u.x()));
    const sim::Approach a = sim::approach_until_contact(s, start, u, start.translation() + 10.0 * u, open);
    // The hand only translated along u.
    EXPECT_TRUE(a.pose.linear().isApprox(start.linear(), 1e-15));
    const Vec3 moved = a.pose.translation() - start.translation();
    EXPECT_LT((moved - moved.dot(u) * u).norm(), 1e-12);
    EXPECT_GT(moved.dot(u), 0.1);
    // The hand's support along the wall's normal (x) ends within the tolerance of the wall.
    const double gap = -support(hand, a.pose, open, Vec3::UnitX());
    EXPECT_GT(gap, 0.0) << "u = " << u.transpose();
    EXPECT_LT(gap, tol) << "u = " << u.transpose();
    EXPECT_GT(a.iterations, 0);
  }
}

TEST(SimApproach, ApproachStopsOnTheTableAndBacksOff) {
  const HandModel hand = fixtures::barrett();
  const GraspSimulator sim(hand, box_mesh(Vec3(1.0, 1.0, 0.0), Vec3(1.05, 1.05, 0.05)));  // far away
  const sim::SimScene& s = sim.scene();
  const Eigen::VectorXd open = hand.coupled_joints(0.3, 0.0);
  const double depth = sim::depth_below_palm(hand, s.links, open);
  const Iso3 start = HandModel::top_grasp_pose(0.0, 0.0, 0.4, 0.5);
  sim::Approach a = sim::approach_until_contact(s, start, -Vec3::UnitZ(), Vec3(0, 0, -1), open);
  const double lowest = a.pose.translation().z() - depth;  // palm down: depth is along world -z
  EXPECT_GT(lowest, 0.0);
  EXPECT_LT(lowest, s.options.contact_tolerance);
  EXPECT_EQ(a.pose.translation().x(), 0.0);
  EXPECT_EQ(a.pose.translation().y(), 0.0);
  const double z = a.pose.translation().z();
  sim::back_off(s, a, 0.02);
  EXPECT_NEAR(a.pose.translation().z(), z + 0.02, 1e-15);
  for (const auto& c : a.distances) EXPECT_FALSE(c.current);
}

namespace {

/// The open hand's lowest point above the table (world z) at hand pose H.
double lowest_z(const HandModel& hand, const Iso3& H, const Eigen::VectorXd& q) { return -support(hand, H, q, -Vec3::UnitZ()); }

/// Random approaches from above onto the object around `centre`.
std::vector<ApproachSpec> random_approaches(int n, const Vec3& centre, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N;
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::vector<ApproachSpec> out(n);
  for (ApproachSpec& a : out) {
    Vec3 u(N(rng), N(rng), N(rng));
    u.z() = std::abs(u.z()) + 1.0;  // mostly within 45 deg of the vertical
    a.direction = -u;               // not normalised: the simulator does it
    a.roll = M_PI * U(rng);
    a.target = centre + 0.01 * Vec3(U(rng), U(rng), U(rng));
  }
  return out;
}

void expect_same_grasp(const GraspResult& a, const GraspResult& b, const std::string& what) {
  EXPECT_EQ(a.joints, b.joints) << what;
  EXPECT_EQ(a.hand_pose.matrix(), b.hand_pose.matrix()) << what;
  EXPECT_EQ(a.stopped_by_table, b.stopped_by_table) << what;
  ASSERT_EQ(a.contacts.size(), b.contacts.size()) << what;
  for (size_t k = 0; k < a.contacts.size(); ++k) {
    EXPECT_EQ(a.contacts[k].link, b.contacts[k].link) << what;
    EXPECT_EQ(a.contacts[k].triangle, b.contacts[k].triangle) << what;
    EXPECT_EQ(a.contacts[k].point, b.contacts[k].point) << what;
  }
}

}  // namespace

// The hand frame of an approach: +z along the direction; roll 0 is the palm-down top-grasp
// hand tilted by the smallest rotation taking -z onto the direction; roll turns it about
// -direction; along -z it is the top grasp's pose itself.
TEST(SimApproach, ApproachPoseConvention) {
  const Vec3 p(0.1, -0.2, 0.3);
  EXPECT_EQ(HandModel::approach_pose(-Vec3::UnitZ(), 0.7, p).matrix(), HandModel::top_grasp_pose(0.1, -0.2, 0.7, 0.3).matrix());
  // Horizontal along +x, roll 0: tilting about -y by 90 deg takes the top grasp's x (world x)
  // to world +z; y = z x x = -y.
  const Iso3 side = HandModel::approach_pose(Vec3(2.0, 0, 0), 0.0, p);
  EXPECT_TRUE(side.linear().col(2).isApprox(Vec3::UnitX(), 1e-15));
  EXPECT_TRUE(side.linear().col(0).isApprox(Vec3::UnitZ(), 1e-15));
  EXPECT_TRUE(side.linear().col(1).isApprox(-Vec3::UnitY(), 1e-15));
  EXPECT_EQ(side.translation(), p);
  // Roll r = a right-handed turn by r about -direction of the roll-0 hand.
  const Vec3 d = Vec3(0.3, -0.5, -0.8).normalized();
  const Iso3 r0 = HandModel::approach_pose(d, 0.0, p), r1 = HandModel::approach_pose(d, 0.9, p);
  EXPECT_TRUE(r1.linear().isApprox(Eigen::AngleAxisd(0.9, -d).toRotationMatrix() * r0.linear(), 1e-12));
  EXPECT_TRUE(r0.linear().col(2).isApprox(d, 1e-12));
  // d = (sin t, 0, -cos t): the tilt is a turn by t about -y, so the roll-0 hand x (world x
  // for the top grasp) becomes (cos t, 0, sin t).
  const double t = 0.6;
  const Iso3 tilted = HandModel::approach_pose(Vec3(std::sin(t), 0, -std::cos(t)), 0.0, p);
  EXPECT_TRUE(tilted.linear().col(0).isApprox(Vec3(std::cos(t), 0, std::sin(t)), 1e-12));
  // From below (d = +z) the tilt is a half turn about world x: Rx(pi) Rz(roll) Rx(pi) = Rz(-roll).
  EXPECT_TRUE(HandModel::approach_pose(Vec3::UnitZ(), 0.5, p).linear().isApprox(
      Eigen::AngleAxisd(-0.5, Vec3::UnitZ()).toRotationMatrix(), 1e-12));
  EXPECT_THROW(HandModel::approach_pose(Vec3::Zero(), 0.0, p), std::invalid_argument);
}

// top_grasp(x, y, yaw, spread, standoff) is the approach along -z with roll = yaw through
// (x, y, any z): the same joints, pose and contacts.
TEST(SimApproach, TopGraspIsTheApproachAlongMinusZ) {
  const HandModel hand = fixtures::barrett();
  const GraspSimulator sim(hand, fixtures::cup_mesh(0.04, 0.035, 0.09, 0.005, 48));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int i = 0; i < 12; ++i) {
    const double x = 0.03 * U(rng), y = 0.03 * U(rng), yaw = M_PI * U(rng), spread = 1.5 + 1.5 * U(rng);
    const double standoff = i % 3 == 0 ? 0.01 : 0.0;
    const GraspResult t = sim.top_grasp(x, y, yaw, spread, standoff);
    const GraspResult a = sim.approach({Vec3(0, 0, -3.0), yaw, Vec3(x, y, 0.2 * (1 + U(rng)))}, spread, standoff);
    expect_same_grasp(t, a, "grasp " + std::to_string(i));
    EXPECT_GE(t.contacts.size(), 1u);
  }
}

// From 45 deg onto a large flat top face: the hand stops when its deepest point along the
// face normal is within the tolerance of the face, then backs off by the stand-off along the
// direction: the palm-to-face distance along the direction (a ray from the palm centre) is
// the contact distance plus the stand-off.
TEST(SimApproach, StandoffIsMeasuredAlongTheDirection) {
  const HandModel hand = fixtures::barrett();
  const double top = 0.3;
  const GraspSimulator sim(hand, box_mesh(Vec3(-0.4, -0.4, 0.0), Vec3(0.4, 0.4, top)));
  const double tol = sim.options().contact_tolerance;
  const Vec3 d = Vec3(1.0, 0.0, -1.0).normalized();
  const Vec3 target(0.0, 0.0, top);
  for (double roll : {0.0, 0.8, 2.0})
    for (double standoff : {0.0, 0.02}) {
      const double spread = 0.5;
      const GraspResult r = sim.approach({d, roll, target}, spread, standoff);
      ASSERT_FALSE(r.collision_at_start);
      EXPECT_FALSE(r.stopped_by_table);
      // the pose: the approach orientation, the palm centre on the line through the target
      EXPECT_TRUE(r.hand_pose.linear().isApprox(HandModel::approach_pose(d, roll, target).linear(), 1e-12));
      const Vec3 p = r.hand_pose.translation();
      EXPECT_LT((p - target).cross(d).norm(), 1e-12);
      // ray from the palm along d to the face z = top, and the same distance at first contact
      const Eigen::VectorXd open = hand.coupled_joints(spread, 0.0);
      const double ray = (p.z() - top) / -d.z();
      const double at_contact = (p.z() - lowest_z(hand, r.hand_pose, open)) / -d.z();
      EXPECT_GT(ray - at_contact - standoff, 0.0) << "roll " << roll;
      EXPECT_LT(ray - at_contact - standoff, tol / -d.z()) << "roll " << roll;
      EXPECT_GT(ray, 0.05);
    }
}

// Descending at 30 deg from the vertical onto an empty part of the table: the hand stops
// with its lowest point within the tolerance of the table, and says so; the same approach
// towards the object is stopped by the object. A horizontal approach that misses the object
// gives up beyond it (the table, parallel to the motion, does not stop it).
TEST(SimApproach, TableStopsAnApproachAndSaysSo) {
  const HandModel hand = fixtures::barrett();
  const GraspSimulator sim(hand, box_mesh(Vec3(0.3, 0.3, 0.0), Vec3(0.36, 0.36, 0.1)));
  const double tol = sim.options().contact_tolerance, spread = 1.0;
  const Eigen::VectorXd open = hand.coupled_joints(spread, 0.0);
  const Vec3 d(std::sin(30 * M_PI / 180), 0.0, -std::cos(30 * M_PI / 180));
  const GraspResult r = sim.approach({d, 0.4, Vec3(-0.1, -0.1, 0.05)}, spread);
  ASSERT_FALSE(r.collision_at_start);
  EXPECT_TRUE(r.stopped_by_table);
  const double low = lowest_z(hand, r.hand_pose, open);
  EXPECT_GT(low, 0.0);
  EXPECT_LT(low, tol);
  EXPECT_LT((r.hand_pose.translation() - Vec3(-0.1, -0.1, 0.05)).cross(d).norm(), 1e-12);
  for (const Contact& c : r.contacts) EXPECT_TRUE(c.on_table);
  // towards the box's top: the object stops it
  const GraspResult o = sim.approach({d, 0.4, Vec3(0.33, 0.33, 0.1)}, spread);
  EXPECT_FALSE(o.stopped_by_table);
  EXPECT_TRUE(std::any_of(o.contacts.begin(), o.contacts.end(), [](const Contact& c) { return !c.on_table; }));
  // a top grasp next to the box lands on the table
  EXPECT_TRUE(sim.top_grasp(0.0, 0.0, 0.0, spread).stopped_by_table);
  // horizontal, 15 cm above the table, beside the box: no stop, no contact, no start collision
  const GraspResult h = sim.approach({Vec3(1, 0, 0), 0.0, Vec3(0.0, 0.0, 0.15)}, 0.0);
  EXPECT_FALSE(h.collision_at_start || h.stopped_by_table);
  EXPECT_TRUE(h.contacts.empty());
  EXPECT_GT(h.hand_pose.translation().x(), 0.36);
}

// A start in the table (a horizontal approach whose open hand reaches below z = 0) is reported,
// not an error; bad arguments are std::invalid_argument naming them.
TEST(SimApproach, StartInTheTableAndBadInput) {
  const HandModel hand = fixtures::barrett();
  const GraspSimulator sim(hand, box_mesh(Vec3(-0.03, -0.03, 0.0), Vec3(0.03, 0.03, 0.2)));
  const GraspResult r = sim.approach({Vec3(1, 0, 0), 0.0, Vec3(0, 0, 0.01)}, 0.0);
  EXPECT_TRUE(r.collision_at_start);
  EXPECT_TRUE(r.contacts.empty());
  EXPECT_EQ(r.joints, hand.coupled_joints(0.0, 0.0));
  const auto message = [&](const ApproachSpec& a) -> std::string {
    try {
      sim.approach(a, 0.0);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(message({Vec3::Zero(), 0.0, Vec3(0, 0, 0.1)}).rfind("direction:", 0), 0u);
  EXPECT_EQ(message({Vec3(NAN, 0, -1), 0.0, Vec3(0, 0, 0.1)}).rfind("direction:", 0), 0u);
  EXPECT_EQ(message({Vec3(0, 0, -1), INFINITY, Vec3(0, 0, 0.1)}).rfind("roll:", 0), 0u);
  EXPECT_EQ(message({Vec3(0, 0, -1), 0.0, Vec3(0, NAN, 0.1)}).rfind("target:", 0), 0u);
  EXPECT_EQ(message({Vec3(0, 0, -1), 0.0, Vec3(0, 0, -0.01)}).rfind("target:", 0), 0u);
  EXPECT_THROW(sim.approach({Vec3(0, 0, -1), 0.0, Vec3(0, 0, 0.1)}, 0.0, -0.01), std::invalid_argument);
  try {
    sim.approach_batch({{Vec3(0, 0, -1), 0.0, Vec3(0, 0, 0.1)}, {Vec3::Zero(), 0.0, Vec3(0, 0, 0.1)}}, 0.0);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("directions[1]:", 0), 0u) << e.what();
  }
  // without a table a target below z = 0 is fine
  SimOptions no_table;
  no_table.table = false;
  EXPECT_NO_THROW(GraspSimulator(hand, box_mesh(Vec3(-0.03, -0.03, -0.1), Vec3(0.03, 0.03, 0.1)), no_table)
                      .approach({Vec3(0, 0, -1), 0.0, Vec3(0, 0, -0.05)}, 0.0));
}

// The batch gives the one-by-one results, for any thread count.
TEST(SimApproach, BatchEqualsOneByOne) {
  const HandModel hand = fixtures::barrett();
  const GraspSimulator sim(hand, fixtures::cup_mesh(0.04, 0.035, 0.09, 0.005, 48));
  const std::vector<ApproachSpec> a = random_approaches(16, Vec3(0, 0, 0.045), 11);
  const GraspBatch b1 = sim.approach_batch(a, 0.6, 0.002, 1), b2 = sim.approach_batch(a, 0.6, 0.002, 2);
  EXPECT_EQ(b1.joints, b2.joints);
  EXPECT_EQ(b1.offsets, b2.offsets);
  int on_object = 0;
  for (int i = 0; i < 16; ++i) {
    const GraspResult g = sim.approach(a[i], 0.6, 0.002);
    EXPECT_EQ(g.joints.transpose(), b1.joints.row(i));
    EXPECT_EQ(g.hand_pose.matrix(), b1.hand_poses[i].matrix());
    EXPECT_EQ(g.stopped_by_table, static_cast<bool>(b1.stopped_by_table[i]));
    EXPECT_EQ(g.collision_at_start, static_cast<bool>(b1.collision_at_start[i]));
    ASSERT_EQ(static_cast<int64_t>(g.contacts.size()), b1.offsets[i + 1] - b1.offsets[i]);
    for (size_t k = 0; k < g.contacts.size(); ++k) {
      EXPECT_EQ(g.contacts[k].point, b1.contacts[b1.offsets[i] + k].point);
      EXPECT_EQ(g.contacts[k].triangle, b1.contacts[b1.offsets[i] + k].triangle);
    }
    on_object += !g.stopped_by_table;
  }
  EXPECT_GT(on_object, 4);
}

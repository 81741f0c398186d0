// Physical lift test: a box squeezed by opposing fingers is lifted with the hand; grasps
// that do not hold it leave it on the table.
#include <gtest/gtest.h>

#include <cmath>

#include "bayesgrasp/physics/lift_test.hpp"

using namespace bayesgrasp;

namespace {

HandModel barrett() {
  return HandModel::from_file(std::string(BAYESGRASP_SOURCE_DIR) + "/python/bayesgrasp/data/hands/barrett_bh8.json");
}

// Axis-aligned box [lo, hi] as a closed, outward-wound triangle mesh.
TriMesh box_mesh(const Vec3& lo, const Vec3& hi) {
  TriMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    m.V.row(i) << ((i & 1) ? hi.x() : lo.x()), ((i & 2) ? hi.y() : lo.y()), ((i & 4) ? hi.z() : lo.z());
  m.F.resize(12, 3);
  m.F << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5;
  return m;
}

double point_box_distance(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 q = p.cwiseMax(lo).cwiseMin(hi);
  return (p - q).norm();
}

// Distance from finger f's phalanx capsules (hand at T, joints q) to the box, by dense
// sampling of the capsule axes (exact point-box distances, 400 samples per link).
double finger_box_distance(const HandModel& hand, int f, const Iso3& T, const Eigen::VectorXd& q, const Vec3& lo,
                           const Vec3& hi) {
  const auto poses = hand.link_poses(T, q);
  double best = 1e9;
  for (const Phalanx& ph : hand.fingers()[f].phalanges)
    for (const Shape& s : ph.shapes) {
      if (s.type != Shape::Type::Capsule) continue;
      for (int k = 0; k <= 400; ++k) {
        const Vec3 p = poses[ph.link] * (s.p0 + (s.p1 - s.p0) * (k / 400.0));
        best = std::min(best, point_box_distance(p, lo, hi) - s.radius);
      }
    }
  return best;
}

// Closes the listed fingers (coupled law, no breakaway needed for a box) until each is
// within 0.1 mm of the box: scan the actuator in 0.01 rad steps to the first penetration,
// then bisect. Other fingers stay open (t = 0).
Eigen::VectorXd touch_joints(const HandModel& hand, const Iso3& T, const Vec3& lo, const Vec3& hi,
                             const std::vector<int>& fingers) {
  Eigen::VectorXd t = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(hand.fingers().size()));
  for (int f : fingers) {
    auto dist = [&](double tf) {
      Eigen::VectorXd tt = t;
      tt[f] = tf;
      return finger_box_distance(hand, f, T, hand.coupled_joints(0.0, tt), lo, hi);
    };
    double a = 0.0, b = 0.0;
    while (b < hand.fingers()[f].t_max() && dist(b) > 0) {
      a = b;
      b += 0.01;
    }
    for (int i = 0; i < 40; ++i) {
      const double m = 0.5 * (a + b);
      (dist(m) > 1e-4 ? a : b) = m;
    }
    t[f] = a;
    EXPECT_NEAR(dist(a), 1e-4, 1e-5) << "finger " << f << " did not reach the box";
  }
  return hand.coupled_joints(0.0, t);
}

// An 8 x 5 x 12 cm box (a carton) standing on the table at the origin, long side along x
// so that fingers 1 and 2, 5 cm apart along x, both press on its face; the palm-down hand
// `gap` above its top face, fingers 1 and 2 on one side and finger 3 on the other
// (spread 0). The box is taller than the fingers' reach, so no finger meets the table.
struct BoxScene {
  explicit BoxScene(double gap = 0.01) : pose(HandModel::top_grasp_pose(0.0, 0.0, 0.0, 0.12 + gap)) {}
  HandModel hand = barrett();
  Vec3 lo{-0.04, -0.025, 0.0}, hi{0.04, 0.025, 0.12};
  TriMesh box = box_mesh(lo, hi);
  Iso3 pose;
};

}  // namespace

TEST(PhysicsLift, WellGraspedBoxIsLifted) {
  BoxScene s;
  const Eigen::VectorXd q = touch_joints(s.hand, s.pose, s.lo, s.hi, {0, 1, 2});
  LiftOptions o;
  o.density = 400.0;  // 192 g
  LiftTester tester(s.hand, s.box, o);
  EXPECT_EQ(tester.shape(), LiftOptions::Shape::ConvexHull);
  EXPECT_NEAR(tester.mass_properties().mass, 0.192, 1e-9);
  const LiftResult r = tester.run(s.pose, q);
  EXPECT_TRUE(r.finite);
  EXPECT_TRUE(r.lifted) << "displacement " << r.displacement;
  EXPECT_LT(r.displacement, 0.01);
  // The squeeze may seat the box against the palm, at most the 1 cm gap; the hand ends
  // lift_height above its start, so the box rises between lift_height and lift_height + gap.
  EXPECT_LE(r.squeeze_displacement, 0.0105);
  // The box's height changes with the palm's (lift_height) plus its own vertical motion
  // relative to the palm (at most the two displacements).
  EXPECT_LE(std::abs(r.height_gain - o.lift_height), r.squeeze_displacement + r.displacement + 1e-9);
  EXPECT_EQ(r.steps, static_cast<int>(std::ceil((o.squeeze_time + o.lift_time + o.shake_time + o.hold_time) / o.time_step - 1e-9)));
}

TEST(PhysicsLift, OpenHandLeavesTheBoxOnTheTable) {
  BoxScene s;
  const Eigen::VectorXd q = s.hand.coupled_joints(0.0, 0.0);  // fingers open, nothing touches
  const LiftResult r = lift_test(s.hand, s.pose, q, s.box);
  EXPECT_TRUE(r.finite);
  EXPECT_FALSE(r.lifted);
  EXPECT_GT(r.displacement, 0.04);  // the test stops once the object is 5 cm away
  EXPECT_NEAR(r.height_gain, 0.0, 2e-3);  // still resting on the table
}

TEST(PhysicsLift, OneFingerCannotLift) {
  BoxScene s;
  const Eigen::VectorXd q = touch_joints(s.hand, s.pose, s.lo, s.hi, {2});
  const LiftResult r = lift_test(s.hand, s.pose, q, s.box);
  EXPECT_FALSE(r.lifted) << "displacement " << r.displacement;
  EXPECT_LT(r.height_gain, 0.02);
}

// A fingertip grasp from above: a flat box (8 x 40 x 2 cm) wider than the open fingers'
// span, the palm 5 cm above it. The fingers close until their tips touch the top face, so every
// contact pushes down on the box: nothing can hold it against gravity, the box stays on
// the table while the hand rises.
TEST(PhysicsLift, FingertipGraspFromAboveDropsTheBox) {
  BoxScene s;
  s.lo = Vec3(-0.04, -0.2, 0.0);
  s.hi = Vec3(0.04, 0.2, 0.02);
  s.box = box_mesh(s.lo, s.hi);
  s.pose = HandModel::top_grasp_pose(0.0, 0.0, 0.0, 0.07);
  const Eigen::VectorXd q = touch_joints(s.hand, s.pose, s.lo, s.hi, {0, 1, 2});
  for (int f = 0; f < 3; ++f) {  // the touching part is the tip, on the top face
    const Vec3 tip = s.hand.fingertip(s.pose, f, q);
    EXPECT_LT(point_box_distance(tip, s.lo, s.hi), 0.01) << "finger " << f;
    EXPECT_GT(tip.z(), s.hi.z()) << "finger " << f;
  }
  const LiftResult r = lift_test(s.hand, s.pose, q, s.box);
  EXPECT_TRUE(r.finite);
  EXPECT_FALSE(r.lifted) << "displacement " << r.displacement;
  EXPECT_NEAR(r.height_gain, 0.0, 2e-3);  // still on the table
}

TEST(PhysicsLift, WithoutATableAnUngraspedObjectFalls) {
  BoxScene s;
  LiftOptions o;
  o.table = false;
  const LiftResult r = lift_test(s.hand, s.pose, s.hand.coupled_joints(0.0, 0.0), s.box, o);
  EXPECT_FALSE(r.lifted);
  EXPECT_LT(r.height_gain, -0.04);  // free fall
}

TEST(PhysicsLift, DeterministicAndBatchEqualsSerial) {
  BoxScene s;
  const Eigen::VectorXd good = touch_joints(s.hand, s.pose, s.lo, s.hi, {0, 1, 2});
  const Eigen::VectorXd open = s.hand.coupled_joints(0.0, 0.0);
  LiftOptions o;
  o.density = 400.0;
  LiftTester tester(s.hand, s.box, o);
  std::vector<Iso3> poses{s.pose, s.pose, s.pose, s.pose};
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(4, good.size());
  J.row(0) = good;
  J.row(1) = open;
  J.row(2) = good;
  J.row(3) = open;
  const auto batch = tester.run_batch(poses, J, 2);
  const LiftResult a = tester.run(s.pose, good), b = tester.run(s.pose, open);
  for (int i : {0, 2}) {
    EXPECT_EQ(batch[i].lifted, a.lifted);
    EXPECT_EQ(batch[i].displacement, a.displacement);
  }
  for (int i : {1, 3}) {
    EXPECT_EQ(batch[i].lifted, b.lifted);
    EXPECT_EQ(batch[i].displacement, b.displacement);
  }
  EXPECT_TRUE(a.lifted);
  EXPECT_FALSE(b.lifted);
}

TEST(PhysicsLift, BadInputThrows) {
  BoxScene s;
  LiftTester tester(s.hand, s.box);
  Eigen::VectorXd q = s.hand.coupled_joints(0.0, 0.0);
  Iso3 bad = s.pose;
  bad.translation().x() = NAN;
  EXPECT_THROW(tester.run(bad, q), std::invalid_argument);
  EXPECT_THROW(tester.run(s.pose, Eigen::VectorXd::Zero(2)), std::invalid_argument);
  LiftOptions o;
  o.density = -1;
  EXPECT_THROW(LiftTester(s.hand, s.box, o), std::invalid_argument);
  TriMesh empty;
  EXPECT_THROW(LiftTester(s.hand, empty), std::invalid_argument);
}

// The tetrahedra skin (for concave objects) gives the same verdicts as the hull on the box,
// and Auto picks it for a concave object (two separate boxes: hull volume >> volume).
TEST(PhysicsLift, TetrahedraShapeAndAutoChoice) {
  BoxScene s;
  LiftOptions o;
  o.density = 400.0;
  o.shape = LiftOptions::Shape::Tetrahedra;
  LiftTester tets(s.hand, s.box, o);
  EXPECT_EQ(tets.shape(), LiftOptions::Shape::Tetrahedra);
  const Eigen::VectorXd good = touch_joints(s.hand, s.pose, s.lo, s.hi, {0, 1, 2});
  EXPECT_TRUE(tets.run(s.pose, good).lifted);
  EXPECT_FALSE(tets.run(s.pose, s.hand.coupled_joints(0.0, 0.0)).lifted);

  TriMesh a = box_mesh(Vec3(-0.05, -0.01, 0), Vec3(-0.03, 0.01, 0.02));
  const TriMesh b = box_mesh(Vec3(0.03, -0.01, 0), Vec3(0.05, 0.01, 0.02));
  TriMesh two;
  two.V.resize(16, 3);
  two.V << a.V, b.V;
  two.F.resize(24, 3);
  two.F << a.F, (b.F.array() + 8).matrix();
  const LiftTester auto_two(s.hand, two);
  EXPECT_EQ(auto_two.shape(), LiftOptions::Shape::Tetrahedra);
  EXPECT_EQ(LiftTester(s.hand, s.box).shape(), LiftOptions::Shape::ConvexHull);
  // Per grasp: the open hand 8 cm above the pair stays outside their hull -> hull; with the
  // palm face 1 cm above the table, the palm (6 cm tall) sits in the gap between the boxes,
  // inside the hull -> tetrahedra.
  const Eigen::VectorXd open = s.hand.coupled_joints(0.0, 0.0);
  EXPECT_FALSE(auto_two.run(HandModel::top_grasp_pose(0, 0, 0, 0.10), open).tetrahedra);
  EXPECT_TRUE(auto_two.run(HandModel::top_grasp_pose(0, 0, 0, 0.01), open).tetrahedra);
}

// Physical lift test: a box squeezed by opposing fingers is lifted with the hand; grasps
// that do not hold it leave it on the table.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "bayesgrasp/physics/lift_test.hpp"
#include "bayesgrasp/physics/squeeze_model.hpp"
#include "physics_fixtures.hpp"

using namespace bayesgrasp;
using namespace bayesgrasp::fixtures;

namespace {

double point_box_distance(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 q = p.cwiseMax(lo).cwiseMin(hi);
  return (p - q).norm();
}

// Closes the listed fingers (coupled law, no breakaway needed for a box) until each is
// within 0.1 mm of the box: scan the actuator in 0.01 rad steps to the first penetration,
// then bisect. Other fingers stay open (t = 0).
Eigen::VectorXd touch_joints(const HandModel& hand, const Iso3& T, const Vec3& lo, const Vec3& hi,
                             const std::vector<int>& fingers) {
  Eigen::VectorXd t = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(hand.fingers().size()));
  auto dist = [&](const Vec3& p) { return point_box_distance(p, lo, hi); };
  for (int f : fingers) {
    double end = 0.0;
    t[f] = touch_actuator(hand, T, t, f, 0.0, dist, nullptr, &end);
    EXPECT_NEAR(end, 1e-4, 1e-5) << "finger " << f << " did not reach the box";
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

// Given mass properties replace the mesh's: a heavier box at the same grasp weighs what it is
// given; ill-formed ones are refused by name.
TEST(PhysicsLift, GivenMassPropertiesReplaceTheMeshIntegral) {
  BoxScene s;
  LiftOptions o;
  o.density = 400.0;
  MassProperties m = LiftTester(s.hand, s.box, o).mass_properties();
  m.inertia *= 0.5 / m.mass;
  m.mass = 0.5;
  const LiftTester given(s.hand, s.box, o, {}, m);
  EXPECT_DOUBLE_EQ(given.mass_properties().mass, 0.5);
  EXPECT_FALSE(given.concave());
  MassProperties bad = m;
  bad.mass = -1.0;
  EXPECT_THROW(LiftTester(s.hand, s.box, o, {}, bad), std::invalid_argument);
  bad = m;
  bad.inertia(0, 1) += 1.0;  // not symmetric
  EXPECT_THROW(LiftTester(s.hand, s.box, o, {}, bad), std::invalid_argument);
  bad = m;
  bad.volume = 0.5 * m.volume;  // the hull is then 2x the volume: concave
  EXPECT_TRUE(LiftTester(s.hand, s.box, o, {}, bad).concave());
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

// ---- concave objects: the convex decomposition against the tetrahedra ----------------------

namespace {




// touch_actuator with the expectations: the finger starts clear of the object and reaches it.
template <class Dist>
double touch_checked(const HandModel& hand, const Iso3& T, const Eigen::VectorXd& t, int f, double t0, Dist dist) {
  double start = 0.0, end = 0.0;
  const double a = fixtures::touch_actuator(hand, T, t, f, t0, dist, &start, &end);
  EXPECT_GT(start, 0.0) << "finger " << f << " starts in contact";
  EXPECT_LT(end, 2e-4) << "finger " << f << " did not reach the object";
  return a;
}

// A pot (outer radius 6 cm, 4 mm wall, 12 cm tall, 8 mm floor, 64 segments: 512 triangles)
// whose centre is 5.8 cm along +y from the palm-down hand's axis, the palm face 1.5 cm above
// its rim: finger 3 (on world +y) hangs into the pot through its opening, fingers 1 and 2
// stay outside, and the wall near the hand's axis is between them.
struct PotScene {
  HandModel hand = barrett();
  double R = 0.06, r = 0.056, h = 0.12, t = 0.008;
  Vec3 c{0.0, 0.058, 0.0};
  TriMesh pot = cup_mesh(R, r, h, t, 64, c);
  std::vector<Eigen::MatrixX3d> pieces = cup_pieces(R, r, h, t, 64, 4, c);
  Iso3 pose = HandModel::top_grasp_pose(0.0, 0.0, 0.0, h + 0.015);
  double dist(const Vec3& p) const { return cup_distance(p, R, r, h, t, c); }
  // Actuator values: finger 3 from hanging at 60 deg (inside the pot) to the inner wall;
  // fingers 1 and 2 (if `pinch`) from open to the outer wall.
  Eigen::VectorXd joints(bool pinch) const {
    Eigen::VectorXd a = Eigen::VectorXd::Zero(3);
    auto d = [this](const Vec3& p) { return dist(p); };
    a[2] = touch_checked(hand, pose, a, 2, M_PI / 3, d);
    if (pinch)
      for (int f : {0, 1}) a[f] = touch_checked(hand, pose, a, f, 0.0, d);
    return hand.coupled_joints(0.0, a);
  }
};

}  // namespace

// Finger 3 inside the pot and fingers 1 and 2 outside pinch its wall: the pot (26 g) is
// carried up with the hand but swings about the pinch (its centre of mass is ~6 cm from the
// fingers), by more than the 2 cm success distance - not lifted, with the tetrahedra and
// with the decomposition alike; finger 3 alone (fingers 1, 2 open) leaves it on the table.
// Auto uses the decomposition for these grasps (finger 3 is inside the hull) when pieces
// are given, the tetrahedra otherwise.
TEST(PhysicsLiftConcave, DecompositionAgreesWithTetrahedraThroughTheOpening) {
  const PotScene s;
  LiftOptions o;
  o.density = 100.0;
  o.shape = LiftOptions::Shape::Tetrahedra;
  const LiftTester tets(s.hand, s.pot, o);
  o.shape = LiftOptions::Shape::Decomposition;
  const LiftTester dec(s.hand, s.pot, o, s.pieces);
  EXPECT_EQ(dec.shape(), LiftOptions::Shape::Decomposition);
  EXPECT_EQ(dec.num_pieces(), 17);
  EXPECT_TRUE(dec.concave());
  const Eigen::VectorXd pinch = s.joints(true), one = s.joints(false);
  const LiftResult tp = tets.run(s.pose, pinch), dp = dec.run(s.pose, pinch);
  const LiftResult t1 = tets.run(s.pose, one), d1 = dec.run(s.pose, one);
  for (const LiftResult* r : {&tp, &dp, &t1, &d1}) EXPECT_TRUE(r->finite);
  for (const LiftResult* r : {&t1, &d1}) EXPECT_FALSE(r->lifted) << "displacement " << r->displacement;
  for (const LiftResult* r : {&tp, &dp}) {  // the pinch on the wall carries the pot up
    EXPECT_GT(r->height_gain, 0.06);
    EXPECT_LT(r->displacement, 0.04);
  }
  EXPECT_EQ(dp.lifted, tp.lifted);
  EXPECT_NEAR(dp.displacement, tp.displacement, 0.01);
  for (const LiftResult* r : {&t1, &d1}) EXPECT_LT(r->height_gain, 0.02);  // left behind (tilted at most)
  EXPECT_EQ(dp.shape, LiftOptions::Shape::Decomposition);
  EXPECT_TRUE(tp.tetrahedra);
  EXPECT_FALSE(dp.tetrahedra);

  o.shape = LiftOptions::Shape::Auto;
  const LiftTester auto_dec(s.hand, s.pot, o, s.pieces), auto_tets(s.hand, s.pot, o);
  EXPECT_EQ(auto_dec.shape(), LiftOptions::Shape::Decomposition);
  EXPECT_EQ(auto_tets.shape(), LiftOptions::Shape::Tetrahedra);
  EXPECT_EQ(auto_tets.num_pieces(), 0);
  const LiftResult ap = auto_dec.run(s.pose, pinch);
  EXPECT_EQ(ap.shape, LiftOptions::Shape::Decomposition);
  EXPECT_EQ(ap.lifted, dp.lifted);
  EXPECT_EQ(ap.displacement, dp.displacement);  // the same simulation
  EXPECT_EQ(auto_tets.run(s.pose, pinch).shape, LiftOptions::Shape::Tetrahedra);
  // The open hand well above the pot stays outside its hull: the hull, either way.
  const Iso3 high = HandModel::top_grasp_pose(0.0, 0.0, 0.0, s.h + 0.08);
  EXPECT_EQ(auto_dec.run(high, s.hand.coupled_joints(0.0, 0.0)).shape, LiftOptions::Shape::ConvexHull);
}

// Skipping the narrowphase for shape pairs proven apart changes nothing but the time: the
// same results, bit for bit, with and without, on the decomposition (finger inside the
// pot), the tetrahedra and the hull (tests/python/test_physics.py checks that the skip is
// used on the mug).
TEST(PhysicsLiftConcave, SkippingSeparatedPairsChangesNothing) {
  const PotScene s;
  BoxScene box;
  LiftOptions o;
  o.density = 100.0;
  auto check = [](const LiftTester& with, const LiftTester& without, const Iso3& pose, const Eigen::VectorXd& q,
                  bool skips = true) {
    const LiftResult a = with.run(pose, q), b = without.run(pose, q);
    EXPECT_EQ(a.shape, b.shape);
    EXPECT_EQ(a.lifted, b.lifted);
    EXPECT_EQ(a.displacement, b.displacement);
    EXPECT_EQ(a.rotation, b.rotation);
    EXPECT_EQ(a.squeeze_displacement, b.squeeze_displacement);
    EXPECT_EQ(a.height_gain, b.height_gain);
    EXPECT_EQ(a.steps, b.steps);
    if (skips) EXPECT_GT(a.skipped_queries, 0);
    EXPECT_EQ(b.skipped_queries, 0);
    return a;
  };
  LiftOptions off = o;
  off.skip_separated_pairs = false;
  o.shape = off.shape = LiftOptions::Shape::Decomposition;
  const LiftResult pinch = check(LiftTester(s.hand, s.pot, o, s.pieces), LiftTester(s.hand, s.pot, off, s.pieces), s.pose,
                                 s.joints(true), false);
  EXPECT_GT(pinch.height_gain, 0.06);  // carried up (the case of DecompositionAgreesWithTetrahedra...)
  check(LiftTester(s.hand, s.pot, o, s.pieces), LiftTester(s.hand, s.pot, off, s.pieces), s.pose, s.joints(false),
        false);
  o.shape = off.shape = LiftOptions::Shape::Tetrahedra;
  check(LiftTester(s.hand, s.pot, o), LiftTester(s.hand, s.pot, off), s.pose, s.joints(false), false);
  o.shape = off.shape = LiftOptions::Shape::Auto;
  o.density = off.density = 400.0;
  const LiftResult held = check(LiftTester(box.hand, box.box, o), LiftTester(box.hand, box.box, off), box.pose,
                                touch_joints(box.hand, box.pose, box.lo, box.hi, {0, 1, 2}), false);
  EXPECT_TRUE(held.lifted);
}

TEST(PhysicsLiftConcave, BadPiecesThrow) {
  const PotScene s;
  LiftOptions o;
  o.shape = LiftOptions::Shape::Decomposition;
  EXPECT_THROW(LiftTester(s.hand, s.pot, o), std::invalid_argument);  // no pieces
  std::vector<Eigen::MatrixX3d> bad = s.pieces;
  bad[3] = Eigen::MatrixX3d::Zero(3, 3);  // too few points
  EXPECT_THROW(LiftTester(s.hand, s.pot, o, bad), std::invalid_argument);
  bad[3] = Eigen::MatrixX3d::Zero(5, 3);
  bad[3].col(0) << 0, 1, 0, 1, 0.5;  // flat: all z = 0
  bad[3].col(1) << 0, 0, 1, 1, 0.5;
  EXPECT_THROW(LiftTester(s.hand, s.pot, o, bad), std::invalid_argument);
  bad[3] = s.pieces[3];
  bad[3](0, 0) = NAN;
  EXPECT_THROW(LiftTester(s.hand, s.pot, o, bad), std::invalid_argument);
  // The hull shape ignores the pieces.
  o.shape = LiftOptions::Shape::ConvexHull;
  EXPECT_EQ(LiftTester(s.hand, s.pot, o, s.pieces).num_pieces(), 0);
}

// ---- the squeeze model (squeeze_model.hpp) ------------------------------------------------------

namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

// The law alone: the closed grasp's breakaway state, the coupling ratio, breakaway on a stalled
// touching proximal (not on a stalled proximal that does not touch), the worm lock.
TEST(SqueezeModel, BreakawayCouplingAndLock) {
  const HandModel hand = barrett();
  const double dt = 1.0 / 480;
  Eigen::VectorXd q = hand.coupled_joints(0.0, 1.0);  // every finger on the closing law
  q[2 + 2] += 0.1;  // finger 2's distal 0.1 rad past the law: it has broken away already
  physics::SqueezeModel m(hand, q, 1.0, 0.5, dt);
  EXPECT_EQ(m.driven(0), 0);
  EXPECT_EQ(m.driven(1), 1);
  EXPECT_EQ(m.driven(2), 0);
  const auto& c = m.commands();
  EXPECT_TRUE(c[1].driven);  // finger 1's proximal: the motor
  EXPECT_DOUBLE_EQ(c[1].velocity, 1.0);
  EXPECT_DOUBLE_EQ(c[1].max_torque, 0.5);
  EXPECT_TRUE(c[2].coupled);  // its distal: the transmission, ratio 1/3 (hand file)
  EXPECT_NEAR(c[2].gear_ratio, 1.0 / 3.0, 1e-12);
  EXPECT_DOUBLE_EQ(c[3].upper, c[3].lower);  // finger 2's proximal: locked
  EXPECT_TRUE(c[4].driven);
  // Stalled (speed 0) for kStallTime: finger 1's proximal touches the object, finger 3's does not.
  std::vector<char> touch(static_cast<size_t>(hand.num_links()), 0);
  touch[hand.fingers()[0].phalanges[0].link] = 1;
  touch[hand.fingers()[2].phalanges[1].link] = 1;  // finger 3's distal touches: no breakaway
  const Eigen::VectorXd still = Eigen::VectorXd::Zero(q.size());
  const int n = static_cast<int>(std::ceil(physics::SqueezeModel::kStallTime / dt - 1e-9));
  for (int k = 0; k < n - 1; ++k) EXPECT_FALSE(m.update(q, still, touch));
  EXPECT_EQ(m.driven(0), 0);
  EXPECT_TRUE(m.update(q, still, touch));
  EXPECT_EQ(m.driven(0), 1);
  EXPECT_EQ(m.driven(2), 0);
  // Worm lock: after the joints reached q + 0.05, the driven ones may not go below it; a
  // coupled one is held by the transmission (its own lower limit the hand file's).
  Eigen::VectorXd up = q.array() + 0.05;
  for (int j = 1; j < up.size(); ++j) up[j] = std::min(up[j], c[j].upper);
  m.update(up, still, touch);
  m.update(q, still, touch);
  EXPECT_NEAR(m.commands()[5].lower, up[5], 1e-12);
  EXPECT_NEAR(m.commands()[4].lower, up[4], 1e-12);
  EXPECT_DOUBLE_EQ(m.commands()[6].lower, hand.fingers()[2].phalanges[1].lower);
  // A proximal at its upper limit hands the motor to the distal.
  Eigen::VectorXd top = q;
  top[5] = hand.fingers()[2].phalanges[0].upper;
  m.update(top, Eigen::VectorXd::Constant(q.size(), 1.0), touch);
  EXPECT_EQ(m.driven(2), 1);
}

namespace {

// The Barrett hand palm-down 30 cm above the table with nothing to grasp but a small block far
// away (a lift test needs an object): each finger closes freely for `time` s.
LiftTrace free_closing(double time, const Eigen::VectorXd& q0) {
  const HandModel hand = barrett();
  const TriMesh far = box_mesh(Vec3(0.5, 0.5, 0.0), Vec3(0.52, 0.52, 0.02));
  LiftOptions o;
  o.squeeze_time = time;
  o.lift_height = 0.0;
  const LiftResult r = LiftTester(hand, far, o).run(HandModel::top_grasp_pose(0, 0, 0, 0.3), q0, 8);
  return *r.trace;
}

}  // namespace

// A finger with no contact closes to its joint limits: the proximal to 140 deg, the distal by
// the coupling (42 + 140 / 3 = 88.7 deg), then - the proximal at its limit - to 90 deg (each
// may then sag by the worm's backlash, at most).
TEST(SqueezeModel, FreeFingerClosesToItsJointLimits) {
  const HandModel hand = barrett();
  const LiftTrace t = free_closing(3.0, hand.coupled_joints(0.0, 0.0));
  const Eigen::VectorXd& q = t.joints.back();
  const double tol = 0.5 * kDeg + LiftOptions{}.worm_backlash;
  for (const Finger& f : hand.fingers()) {
    EXPECT_NEAR(q[f.first_joint], 140 * kDeg, tol) << f.name;
    EXPECT_NEAR(q[f.first_joint + 1], 90 * kDeg, tol) << f.name;
    EXPECT_EQ(t.driven.back()[&f - &hand.fingers()[0]], 1) << f.name;
  }
  EXPECT_TRUE(t.contacts.empty());
}

// Before breakaway the distal follows the proximal at the hand file's ratio (1/3), and the
// proximal closes at closing_speed (1 rad/s) once under way.
TEST(SqueezeModel, CouplingRatioHoldsBeforeBreakaway) {
  const HandModel hand = barrett();
  const Eigen::VectorXd q0 = hand.coupled_joints(0.0, 0.3);
  const LiftTrace t = free_closing(0.8, q0);
  int checked = 0;
  for (size_t s = 0; s < t.time.size(); ++s) {
    if (t.driven[s].maxCoeff() > 0) break;
    for (const Finger& f : hand.fingers()) {
      const double dp = t.joints[s][f.first_joint] - q0[f.first_joint];
      const double dd = t.joints[s][f.first_joint + 1] - q0[f.first_joint + 1];
      EXPECT_NEAR(dd, dp / 3.0, 2e-3) << f.name << " at " << t.time[s];
      if (t.time[s] > 0.1) EXPECT_NEAR(dp, t.time[s], 0.02) << f.name << " at " << t.time[s];
    }
    ++checked;
  }
  EXPECT_GT(checked, 40);
}

// A block under finger 3's proximal (not its distal): the proximal closes onto it and stops,
// the finger breaks away and the distal alone closes on to its 90 deg limit, past the coupling.
TEST(SqueezeModel, ProximalStoppedByABoxLetsTheDistalBreakAway) {
  const HandModel hand = barrett();
  const double palm_z = 0.15;
  // Finger 3 points along world +y (top grasp, yaw 0); its proximal joint is 5 cm out, the
  // link 7 cm long: the block spans y in [4, 9] cm, its top 4 cm below the palm face.
  const TriMesh block = box_mesh(Vec3(-0.03, 0.04, 0.0), Vec3(0.03, 0.09, palm_z - 0.04));
  LiftOptions o;
  o.density = 8000.0;  // heavy: it stays put
  o.squeeze_time = 1.5;
  o.lift_height = 0.0;
  Eigen::VectorXd t = Eigen::VectorXd::Zero(3);
  t[0] = t[1] = 0.0;
  const Eigen::VectorXd q0 = hand.coupled_joints(0.0, t);
  const LiftResult r = LiftTester(hand, block, o).run(HandModel::top_grasp_pose(0, 0, 0, palm_z), q0, 8);
  EXPECT_EQ(r.breakaway[2], 1);
  const LiftTrace& tr = *r.trace;
  const int p3 = hand.fingers()[2].first_joint, d3 = p3 + 1;
  const Eigen::VectorXd& q = tr.joints.back();
  EXPECT_GT(q[p3], 10 * kDeg);   // it closed onto the block
  EXPECT_LT(q[p3], 60 * kDeg);   // and was stopped by it
  EXPECT_NEAR(q[d3], 90 * kDeg, 0.5 * kDeg + o.worm_backlash);
  EXPECT_GT(q[d3] - (42 * kDeg + q[p3] / 3.0), 0.2);  // past the coupling
  bool proximal_touched = false;
  for (const LiftContact& c : tr.contacts) proximal_touched |= c.link == hand.fingers()[2].phalanges[0].link;
  EXPECT_TRUE(proximal_touched);
}

// Worm drive: lifting and shaking a held box loads the fingers, yet no joint ever opens by
// more than the worm's backlash (each angle stays at least the largest it reached minus the
// backlash, within the solver's tolerance).
TEST(SqueezeModel, JointsUnderLoadDoNotOpen) {
  BoxScene s;
  const Eigen::VectorXd q = touch_joints(s.hand, s.pose, s.lo, s.hi, {0, 1, 2});
  LiftOptions o;
  o.density = 400.0;
  const LiftResult r = LiftTester(s.hand, s.box, o).run(s.pose, q, 1);
  EXPECT_TRUE(r.lifted);
  Eigen::VectorXd reached = q;
  double worst = 0.0;  // the most a joint fell below the largest angle it had reached
  for (const Eigen::VectorXd& qs : r.trace->joints) {
    for (int j = 1; j < qs.size(); ++j) worst = std::max(worst, reached[j] - qs[j]);
    reached = reached.cwiseMax(qs);
  }
  EXPECT_LT(worst, o.worm_backlash + 3e-3) << "rad";
  EXPECT_EQ(r.trace->time.size(), static_cast<size_t>(r.steps));
}

// The script's number of steps is bounded and positive: no overflow, no endless runs.
TEST(PhysicsLift, TooManyStepsThrow) {
  BoxScene s;
  LiftOptions o;
  o.squeeze_time = 5e6;  // 2.4e9 steps: used to overflow into steps = 0 and "lifted"
  EXPECT_THROW(LiftTester(s.hand, s.box, o), std::invalid_argument);
  o = LiftOptions{};
  o.time_step = 1e-9;  // 1.15e9 steps: used to run for minutes
  try {
    LiftTester(s.hand, s.box, o);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("time_step"), std::string::npos) << e.what();
  }
  o.time_step = 1e-6;  // 1.15e6 steps: allowed
  EXPECT_NO_THROW(LiftTester(s.hand, s.box, o));
}

// The approach step (sim/approach.hpp) along directions other than the top grasps' -z, against
// where the first contact must be: the open hand's support along a wall's normal (the largest
// coordinate of its capsules and boxes, computed here from the hand file's shapes) within the
// contact tolerance of the wall.
#include <gtest/gtest.h>

#include <cmath>

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
    const sim::Approach a = sim::approach_until_contact(s, start, u, Vec3::Constant(10.0), open);
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

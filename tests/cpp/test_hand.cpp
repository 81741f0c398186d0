#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bayesgrasp/hand/hand_model.hpp"

using namespace bayesgrasp;

namespace {
const std::string kBarrett = std::string(BAYESGRASP_SOURCE_DIR) + "/python/bayesgrasp/data/hands/barrett_bh8.json";
constexpr double kDeg = M_PI / 180.0;
}  // namespace

TEST(Hand, BarrettStructure) {
  const HandModel h = HandModel::from_file(kBarrett);
  EXPECT_EQ(h.fingers().size(), 3u);
  EXPECT_EQ(h.num_joints(), 7);             // spread + 3 x (proximal, distal)
  EXPECT_EQ(h.num_links(), 1 + 2 + 6);      // palm, two knuckles with shapes, six phalanges
  EXPECT_NEAR(h.spread_upper(), M_PI, 1e-12);
}

TEST(Hand, BarrettFlatFingertipsFromPublishedLengths) {
  const HandModel h = HandModel::from_file(kBarrett);
  // Open hand, spread 0: proximal 0, distal at its 42 deg offset.
  const Eigen::VectorXd q = h.coupled_joints(0.0, 0.0);
  EXPECT_NEAR(q[1], 0.0, 1e-12);
  EXPECT_NEAR(q[2], 42 * kDeg, 1e-12);
  // Finger 3: joint at 50 mm on -y; proximal 70 mm flat; distal 55 mm at 42 deg towards +z.
  const Vec3 tip3 = h.fingertip(Iso3::Identity(), 2, q);
  EXPECT_NEAR(tip3.x(), 0.0, 1e-12);
  EXPECT_NEAR(tip3.y(), -(0.05 + 0.07 + 0.055 * std::cos(42 * kDeg)), 1e-12);
  EXPECT_NEAR(tip3.z(), 0.055 * std::sin(42 * kDeg), 1e-12);
  // Finger 1: spread axis at x = +25 mm, knuckle 50 mm along +y at spread 0.
  const Vec3 tip1 = h.fingertip(Iso3::Identity(), 0, q);
  EXPECT_NEAR(tip1.x(), 0.025, 1e-12);
  EXPECT_NEAR(tip1.y(), 0.05 + 0.07 + 0.055 * std::cos(42 * kDeg), 1e-12);
}

TEST(Hand, BarrettSpreadAndClosing) {
  const HandModel h = HandModel::from_file(kBarrett);
  // Spread 90 deg: fingers 1 and 2 oppose each other along x.
  const double t = 90 * kDeg;  // proximal at 90 deg: along the approach axis
  const Eigen::VectorXd q = h.coupled_joints(M_PI / 2, t);
  EXPECT_NEAR(q[2], 30 * kDeg + 42 * kDeg, 1e-12);  // distal = proximal / 3 + 42
  const double dist_angle = 90 * kDeg + 72 * kDeg;  // cumulative distal angle from the palm plane
  const Vec3 tip1 = h.fingertip(Iso3::Identity(), 0, q);
  EXPECT_NEAR(tip1.x(), 0.025 + 0.05 + 0.055 * std::cos(dist_angle), 1e-12);
  EXPECT_NEAR(tip1.y(), 0.0, 1e-12);
  EXPECT_NEAR(tip1.z(), 0.07 + 0.055 * std::sin(dist_angle), 1e-12);
  const Vec3 tip2 = h.fingertip(Iso3::Identity(), 1, q);
  EXPECT_NEAR(tip2.x(), -tip1.x(), 1e-12);
  // Limits: the coupling clamps at 140 deg proximal and 88.67 deg distal.
  const Eigen::VectorXd closed = h.coupled_joints(0.0, 10.0);
  EXPECT_NEAR(closed[1], 140 * kDeg, 1e-12);
  EXPECT_NEAR(closed[2], 90 * kDeg, 1e-12);
  EXPECT_NEAR(h.fingers()[0].t_max(), 144 * kDeg, 1e-9);  // distal reaches 90 at t = 144 deg
}

TEST(Hand, LinkPosesMatchThePlanarChain) {
  const HandModel h = HandModel::from_file(kBarrett);
  const Iso3 T = HandModel::top_grasp_pose(0.1, 0.2, 0.3, 0.25);
  const Eigen::VectorXd q = h.coupled_joints(0.4, 1.0);
  const auto poses = h.link_poses(T, q);
  ASSERT_EQ(static_cast<int>(poses.size()), h.num_links());
  EXPECT_TRUE(poses[0].isApprox(T));
  // Palm down: hand +z is world -z.
  EXPECT_TRUE((T.linear() * Vec3::UnitZ()).isApprox(-Vec3::UnitZ(), 1e-12));
  for (int f = 0; f < 3; ++f) {
    // Oracle: each finger is a planar chain in the plane spanned by its outward direction d
    // (yaw = base_yaw + spread_sign * spread) and the hand's +z. The proximal joint sits at
    // base + knuckle * d, the distal joint 70 mm further along the proximal direction
    // (cumulative angle q1), the fingertip 55 mm along the distal direction (angle q1 + q2).
    const Finger& F = h.fingers()[f];
    const double yaw = F.base_yaw + F.spread_sign * q[0];
    const Vec3 d(std::cos(yaw), std::sin(yaw), 0.0);
    const double a1 = q[F.first_joint], a2 = a1 + q[F.first_joint + 1];
    const Vec3 x1 = std::cos(a1) * d + std::sin(a1) * Vec3::UnitZ();
    const Vec3 x2 = std::cos(a2) * d + std::sin(a2) * Vec3::UnitZ();
    const Vec3 prox_joint = F.base + F.knuckle_length * d;
    const Vec3 dist_joint = prox_joint + 0.07 * x1;
    const int prox = F.phalanges[0].link, distal = F.phalanges[1].link;
    EXPECT_TRUE(poses[prox].translation().isApprox(T * prox_joint, 1e-12));
    EXPECT_TRUE(poses[distal].translation().isApprox(T * dist_joint, 1e-12));
    EXPECT_TRUE(poses[distal].linear().col(0).isApprox(T.linear() * x2, 1e-12));
    EXPECT_TRUE(poses[distal].linear().col(1).isApprox(T.linear() * d.cross(Vec3::UnitZ()), 1e-12));
    EXPECT_TRUE(h.phalanx_pose(T, f, 1, q).translation().isApprox(T * dist_joint, 1e-12));
    EXPECT_TRUE(h.fingertip(T, f, q).isApprox(T * (dist_joint + 0.055 * x2), 1e-12));
    Iso3 chain[2];
    h.phalanx_poses(T, f, q[0], q.data() + F.first_joint, chain);
    EXPECT_TRUE(chain[1].translation().isApprox(T * dist_joint, 1e-12));
    EXPECT_TRUE(chain[0].linear().col(0).isApprox(T.linear() * x1, 1e-12));
  }
}

TEST(Hand, RejectsBadFilesAndJoints) {
  EXPECT_THROW(HandModel::from_json("{not json"), std::invalid_argument);
  EXPECT_THROW(HandModel::from_json(R"({"name": "x"})"), std::invalid_argument);
  EXPECT_THROW(HandModel::from_file("/nonexistent/hand.json"), std::invalid_argument);
  const HandModel h = HandModel::from_file(kBarrett);
  Eigen::VectorXd q = h.coupled_joints(0.0, 0.5);
  EXPECT_NO_THROW(h.check_joints(q));
  q[1] = 3.0;
  EXPECT_THROW(h.check_joints(q), std::invalid_argument);
  EXPECT_THROW(h.check_joints(Eigen::VectorXd::Zero(3)), std::invalid_argument);
  EXPECT_NO_THROW(h.check_spread(M_PI));
  EXPECT_THROW(h.check_spread(M_PI + 1e-6), std::invalid_argument);
  EXPECT_THROW(h.check_spread(NAN), std::invalid_argument);
  EXPECT_THROW(h.phalanx_pose(Iso3::Identity(), 0, 2, q), std::invalid_argument);
}

// Issue 31: a hand file is strict - an unknown or a missing key throws, naming where it is.
TEST(Hand, StrictKeys) {
  std::ifstream in(kBarrett);
  std::stringstream ss;
  ss << in.rdbuf();
  const nlohmann::json spec = nlohmann::json::parse(ss.str());
  auto message = [](const nlohmann::json& j) {
    try {
      HandModel::from_json(j.dump());
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  nlohmann::json no_knuckle = spec;
  no_knuckle["fingers"][2].erase("knuckle");
  EXPECT_NE(message(no_knuckle).find("fingers[2]: missing key 'knuckle'"), std::string::npos);
  nlohmann::json extra = spec;
  extra["fingers"][0]["phalanges"][1]["stiffness"] = 3.0;
  EXPECT_NE(message(extra).find("fingers[0].phalanges[1]: unknown key 'stiffness'"), std::string::npos);
  nlohmann::json no_ratio = spec;
  no_ratio["fingers"][1]["phalanges"][0].erase("ratio");
  EXPECT_NE(message(no_ratio).find("missing key 'ratio'"), std::string::npos);
  EXPECT_EQ(message(spec), "");
}

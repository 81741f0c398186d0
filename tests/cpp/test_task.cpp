// Eq. 4.1's pieces against values derived by hand: the pose densities, the mixture sum and its
// per-model shares, local pose coordinates, and the open hand's clearance from the table and a cloud.
#include <gtest/gtest.h>

#include <cmath>

#include "bayesgrasp/task/grasp_mixture.hpp"
#include "bayesgrasp/task/hand_clearance.hpp"
#include "bayesgrasp/task/pose_density.hpp"

using namespace bayesgrasp;
using namespace bayesgrasp::task;

namespace {
const std::string kBarrett = std::string(BAYESGRASP_SOURCE_DIR) + "/python/bayesgrasp/data/hands/barrett_bh8.json";

Iso3 pose(double x, double y, double z, double yaw = 0.0) {
  Iso3 T = Iso3::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  T.translation() = Vec3(x, y, z);
  return T;
}

PoseDensity density(DensityKind k) {
  PoseDensity d;
  d.kind = k;
  d.translation_scale = 0.01;
  d.rotation_scale = 0.2;
  return d;
}
}  // namespace

TEST(Task, DensitiesByHand) {
  const PoseDensity lap = density(DensityKind::Laplace), gau = density(DensityKind::Gaussian);
  PoseDensity reg = density(DensityKind::RegularisedGaussian);
  EXPECT_DOUBLE_EQ(lap(0, 0), 1.0);
  EXPECT_NEAR(lap(0.01, 0.0), std::exp(-1.0), 1e-15);
  EXPECT_NEAR(lap(0.01, 0.2), std::exp(-2.0), 1e-15);
  EXPECT_NEAR(gau(0.01, 0.0), std::exp(-0.5), 1e-15);
  EXPECT_NEAR(gau(0.02, 0.2), std::exp(-0.5 * 5.0), 1e-15);
  // regularised: (1 - 0.2) exp(-a^2/2) + 0.2 exp(-a^2/(2 * 16)) at a = 3
  EXPECT_NEAR(reg(0.03, 0.0), 0.8 * std::exp(-4.5) + 0.2 * std::exp(-4.5 / 16.0), 1e-15);
  // far from the grasp the wide component dominates: the regularised form keeps a gradient
  EXPECT_GT(reg(0.08, 0.0), 1e3 * gau(0.08, 0.0));
  reg.wide_weight = 1.5;
  EXPECT_THROW(reg.validate(), std::invalid_argument);
  PoseDensity bad = lap;
  bad.translation_scale = 0.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

TEST(Task, RotationAngleOfKnownRotations) {
  const Mat3 I = Mat3::Identity();
  EXPECT_NEAR(rotation_angle(I, Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix()), 0.3, 1e-12);
  EXPECT_NEAR(rotation_angle(I, Eigen::AngleAxisd(M_PI, Vec3::UnitX()).toRotationMatrix()), M_PI, 1e-7);
  EXPECT_NEAR(rotation_angle(I, I), 0.0, 1e-7);
}

TEST(Task, MixtureSumsWeightedDensitiesAndSplitsByModel) {
  // two models; model 0 has two grasps, model 1 one
  const std::vector<Iso3> grasps = {pose(0, 0, 0), pose(0.02, 0, 0), pose(0, 0, 0, 0.4)};
  const Eigen::VectorXd w = (Eigen::VectorXd(3) << 0.5, 0.25, 2.0).finished();
  const GraspMixture mix(grasps, w, {0, 0, 1}, 2);
  const PoseDensity lap = density(DensityKind::Laplace);
  const MixtureValues v = mix.evaluate({pose(0, 0, 0), pose(0.01, 0, 0, 0.2)}, lap, true);
  // at grasp 0: 0.5 * 1 + 0.25 e^-2 + 2 e^-(0.4/0.2)
  EXPECT_NEAR(v.value[0], 0.5 + 0.25 * std::exp(-2.0) + 2.0 * std::exp(-2.0), 1e-12);
  EXPECT_NEAR(v.per_model(0, 0), 0.5 + 0.25 * std::exp(-2.0), 1e-12);
  EXPECT_NEAR(v.per_model(0, 1), 2.0 * std::exp(-2.0), 1e-12);
  EXPECT_EQ(v.dominant[0], 0);
  // at (1 cm, yaw 0.2): every component is 1 cm / 0.2 rad away (grasp 2: 0.2 rad): e^-2, e^-2, e^-(1 + 1)
  EXPECT_NEAR(v.value[1], (0.5 + 0.25 + 2.0) * std::exp(-2.0), 1e-12);
  EXPECT_EQ(v.dominant[1], 2);
  EXPECT_NEAR(v.per_model.row(1).sum(), v.value[1], 1e-15);
  // threads do not change the values
  const MixtureValues v2 = mix.evaluate({pose(0, 0, 0), pose(0.01, 0, 0, 0.2)}, lap, true, 0);
  EXPECT_EQ(v.value, v2.value);
  EXPECT_THROW(GraspMixture(grasps, w, {0, 0, 2}, 2), std::invalid_argument);
  EXPECT_THROW(GraspMixture(grasps, -w, {0, 0, 1}, 2), std::invalid_argument);
}

TEST(Task, LocalPosesAroundAReference) {
  const Iso3 ref = pose(0.1, 0.2, 0.3, 0.5);
  LocalPoses X(2, 6);
  X << 0, 0, 0, 0, 0, 0, 0.01, -0.02, 0.03, 0, 0, 0.25;
  const std::vector<Iso3> A = poses_from_local(ref, X);
  EXPECT_TRUE(A[0].isApprox(ref, 1e-15));
  EXPECT_TRUE(A[1].translation().isApprox(Vec3(0.11, 0.18, 0.33), 1e-15));
  EXPECT_NEAR(rotation_angle(A[1].linear(), pose(0, 0, 0, 0.75).linear()), 0.0, 1e-7);
}

TEST(Task, OpenHandClearanceFromTableAndCloud) {
  const HandModel hand = HandModel::from_file(kBarrett);
  const Eigen::VectorXd q = hand.coupled_joints(0.0, 0.0);
  // palm down (hand +z = world -z) with the palm face at height z: the palm box (60 mm deep,
  // behind the face) is above; the flat open fingers reach at most their capsule radius and the
  // distal links' tilt below the face.
  const Iso3 high = HandModel::top_grasp_pose(0, 0, 0, 0.3);
  const Iso3 low = HandModel::top_grasp_pose(0, 0, 0, -0.01);
  CloudPoints none(0, 3);
  const Clearance c = hand_clearance(hand, q, {high, low}, none);
  EXPECT_EQ(c.table[0], 0.0);
  // the lowest point of the open hand lies below the palm face by its downward reach
  const Clearance at_face = hand_clearance(hand, q, {HandModel::top_grasp_pose(0, 0, 0, 0.0)}, none);
  EXPECT_NEAR(c.table[1], at_face.table[0] + 0.01, 1e-12);
  EXPECT_GT(at_face.table[0], 0.0125 - 1e-12);  // at least a capsule radius below the face
  // a cloud point at the palm box's centre (30 mm behind the face): 30 mm deep (box half height)
  CloudPoints p(2, 3);
  p << 0, 0, 0.33, 0.5, 0.5, 0.5;
  const Clearance cc = hand_clearance(hand, q, {high}, p);
  EXPECT_NEAR(cc.cloud[0], 0.03, 1e-12);
  ClearanceOptions grown;
  grown.margin = 0.002;
  EXPECT_NEAR(hand_clearance(hand, q, {high}, p, grown).cloud[0], 0.032, 1e-12);
  EXPECT_THROW(hand_clearance(hand, q.head(3), {high}, p), std::invalid_argument);
}

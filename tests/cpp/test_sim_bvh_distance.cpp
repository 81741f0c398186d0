// bvh_distance against brute force over all triangle pairs, and its pruning of tied pairs.
#include <gtest/gtest.h>

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/detail/primitive_shape_algorithm/triangle_distance.h>

#include <cmath>
#include <random>

#include "bayesgrasp/sim/bvh_distance.hpp"
#include "bayesgrasp/sim/link_geometry.hpp"

using namespace bayesgrasp;
using namespace bayesgrasp::sim;

namespace {

const double kTie = SimOptions().tie_tolerance;

/// Box [-hx, hx] x [-hy, hy] x [-hz, hz], each face an n x n grid of squares split in two.
TriMesh grid_box(double hx, double hy, double hz, int n) {
  std::vector<Vec3> V;
  std::vector<Eigen::Vector3i> F;
  const Vec3 h(hx, hy, hz);
  for (int axis = 0; axis < 3; ++axis) {
    for (int side : {-1, 1}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const int base = static_cast<int>(V.size());
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
          Vec3 p;
          p[axis] = side * h[axis];
          p[u] = h[u] * (2.0 * i / n - 1.0);
          p[v] = h[v] * (2.0 * j / n - 1.0);
          V.push_back(p);
        }
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const int a = base + i * (n + 1) + j, b = a + n + 1;
          // outward winding: (u, v, axis) is right-handed, so +side keeps u x v along +axis
          if (side > 0) {
            F.emplace_back(a, b, b + 1);
            F.emplace_back(a, b + 1, a + 1);
          } else {
            F.emplace_back(a, b + 1, b);
            F.emplace_back(a, a + 1, b + 1);
          }
        }
    }
  }
  TriMesh m;
  m.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (size_t k = 0; k < V.size(); ++k) m.V.row(static_cast<Eigen::Index>(k)) = V[k].transpose();
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (size_t k = 0; k < F.size(); ++k) m.F.row(static_cast<Eigen::Index>(k)) = F[k].transpose();
  return m;
}

/// A 5 cm finger axis along z as one sliver triangle (as the simulator models a capsule's axis).
std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> sliver() {
  auto m = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  const std::vector<fcl::Vector3d> v = {{0, 0, -0.025}, {0, 0, 0.025}, {0, 0, 0.025 + 1e-9}};
  m->beginModel();
  m->addSubModel(v, std::vector<fcl::Triangle>{fcl::Triangle(0, 1, 2)});
  m->endModel();
  return m;
}

/// The finger at `gap` from the box's +x face (x = 0.03), tilted by `tilt` about y.
fcl::Transform3d finger_pose(double gap, double tilt, double y = 0.003, double z = 0.001) {
  fcl::Transform3d T = fcl::Transform3d::Identity();
  T.linear() = Eigen::AngleAxisd(tilt, Vec3::UnitY()).toRotationMatrix();
  T.translation() = Vec3(0.03 + gap, y, z);
  return T;
}

double brute_force(const TriMesh& m, const fcl::BVHModel<fcl::OBBRSSd>& link, const fcl::Transform3d& T) {
  double best = kInf;
  const auto& lv = link.vertices;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Vec3 a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    fcl::Vector3d P, Q;
    best = std::min(best, fcl::detail::TriangleDistance<double>::triDistance(a, b, c, lv[0], lv[1], lv[2], T, P, Q));
  }
  return best;
}

}  // namespace

TEST(BvhDistance, EqualsTheMinimumOverAllTrianglePairs) {
  const TriMesh box = grid_box(0.03, 0.02, 0.05, 24);
  const ObjectGeometry obj = make_object_geometry(box, SimOptions::Bv::OBBRSS);
  const auto link = sliver();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> gap(-0.002, 0.02), tilt(-0.3, 0.3), y(-0.03, 0.03), z(-0.06, 0.06);
  for (int k = 0; k < 40; ++k) {
    // every fourth pose exactly parallel to the face: the tied case
    const fcl::Transform3d T = finger_pose(gap(rng), k % 4 == 0 ? 0.0 : tilt(rng), y(rng), z(rng));
    fcl::DistanceRequestd req;
    fcl::DistanceResultd res;
    bvh_distance(obj.bvh.get(), link.get(), T, req, res, kTie);
    const double exact = brute_force(box, *link, T);
    if (exact <= 0.0) {
      EXPECT_LE(res.min_distance, 0.0) << "pose " << k;
    } else {
      EXPECT_GE(res.min_distance, exact) << "pose " << k;
      EXPECT_LE(res.min_distance, exact + kTie) << "pose " << k;
    }
  }
}

TEST(BvhDistance, PrunesTiedTrianglesUnderAParallelFinger) {
  // 49,152 triangles; a finger 0.1 mm from a face and parallel to it is equally near the ~60
  // triangles under it. Without the tie allowance FCL tests 494 bounding-volume pairs here
  // (and visits 59 leaves); with it, 62.
  const TriMesh box = grid_box(0.03, 0.02, 0.05, 64);
  const ObjectGeometry obj = make_object_geometry(box, SimOptions::Bv::OBBRSS);
  const auto link = sliver();
  const fcl::Transform3d T = finger_pose(1e-4, 0.0);
  fcl::DistanceRequestd req;
  fcl::DistanceResultd tied, exact;
  int tests = -1, fcl_tests = -1;
  bvh_distance(obj.bvh.get(), link.get(), T, req, tied, kTie, &tests);
  bvh_distance(obj.bvh.get(), link.get(), T, req, exact, 0.0, &fcl_tests);  // FCL's own pruning
  EXPECT_NEAR(tied.min_distance, 1e-4, 1e-15);
  EXPECT_EQ(tied.min_distance, exact.min_distance);
  EXPECT_GT(tests, 0);
  EXPECT_LT(tests, 150);
  EXPECT_GT(fcl_tests, 3 * tests);
}

TEST(BvhDistance, APresetCapAboveTheDistanceFindsTheSamePair) {
  const TriMesh box = grid_box(0.03, 0.02, 0.05, 16);
  const ObjectGeometry obj = make_object_geometry(box, SimOptions::Bv::OBBRSS);
  const auto link = sliver();
  const fcl::Transform3d T = finger_pose(0.004, 0.05);  // the lower end 2.75 mm from the face
  fcl::DistanceRequestd req;
  fcl::DistanceResultd open, capped, below;
  bvh_distance(obj.bvh.get(), link.get(), T, req, open, kTie);
  ASSERT_GT(open.min_distance, 0.002);
  capped.min_distance = 0.01;
  bvh_distance(obj.bvh.get(), link.get(), T, req, capped, kTie);
  EXPECT_EQ(open.min_distance, capped.min_distance);
  EXPECT_EQ(open.b1, capped.b1);
  below.min_distance = 0.001;  // nothing nearer than the cap: no pair is found
  bvh_distance(obj.bvh.get(), link.get(), T, req, below, kTie);
  EXPECT_TRUE(below.b1 == fcl::DistanceResultd::NONE);  // (EXPECT_EQ would odr-use NONE)
}

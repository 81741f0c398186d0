#include <gtest/gtest.h>

#include "bayesgrasp/geometry/mesh.hpp"
#include "bayesgrasp/geometry/surface_sampling.hpp"

using namespace bayesgrasp;

namespace {
// Axis-aligned box [0,a]x[0,b]x[0,c] with outward-wound faces.
TriMesh box(double a, double b, double c) {
  TriMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) m.V.row(i) << (i & 1 ? a : 0), (i & 2 ? b : 0), (i & 4 ? c : 0);
  m.F.resize(12, 3);
  m.F << 0, 2, 1, 1, 2, 3,  // z = 0 (normal -z)
      4, 5, 6, 5, 7, 6,     // z = c
      0, 1, 4, 1, 5, 4,     // y = 0
      2, 6, 3, 3, 6, 7,     // y = b
      0, 4, 2, 2, 4, 6,     // x = 0
      1, 3, 5, 3, 7, 5;     // x = a
  return m;
}
}  // namespace

TEST(Geometry, BoxMassProperties) {
  const double a = 0.1, b = 0.2, c = 0.3, rho = 500.0;
  const MassProperties mp = mass_properties(box(a, b, c), rho);
  EXPECT_NEAR(mp.volume, a * b * c, 1e-12);
  EXPECT_NEAR(mp.mass, rho * a * b * c, 1e-9);
  EXPECT_TRUE(mp.com.isApprox(Vec3(a / 2, b / 2, c / 2), 1e-12));
  const double m = mp.mass;
  EXPECT_NEAR(mp.inertia(0, 0), m * (b * b + c * c) / 12, 1e-12);
  EXPECT_NEAR(mp.inertia(1, 1), m * (a * a + c * c) / 12, 1e-12);
  EXPECT_NEAR(mp.inertia(2, 2), m * (a * a + b * b) / 12, 1e-12);
  EXPECT_NEAR(mp.inertia(0, 1), 0.0, 1e-12);
}

TEST(Geometry, InvertedWindingGivesNegativeVolume) {
  TriMesh m = box(1, 1, 1);
  m.F.col(1).swap(m.F.col(2));
  EXPECT_NEAR(mass_properties(m, 1.0).volume, -1.0, 1e-12);
  EXPECT_NEAR(mass_properties(m, 1.0).mass, 1.0, 1e-12);
}

TEST(Geometry, RejectsBadMeshes) {
  TriMesh empty;
  EXPECT_THROW(validate_mesh(empty), std::invalid_argument);
  TriMesh m = box(1, 1, 1);
  m.F(0, 0) = 8;
  EXPECT_THROW(validate_mesh(m), std::invalid_argument);
  m = box(1, 1, 1);
  m.V(0, 0) = std::nan("");
  EXPECT_THROW(validate_mesh(m), std::invalid_argument);
  EXPECT_THROW(mass_properties(box(1, 1, 1), -1.0), std::invalid_argument);
}

TEST(Geometry, PlanarPoseAndMatrix) {
  const Iso3 T = planar_pose(0.1, -0.2, M_PI / 2);
  EXPECT_TRUE((T * Vec3(1, 0, 0)).isApprox(Vec3(0.1, 0.8, 0.0), 1e-12));
  EXPECT_TRUE(pose_from_matrix(T.matrix()).isApprox(T));
  Eigen::Matrix4d bad = T.matrix();
  bad(0, 0) = 2.0;
  EXPECT_THROW(pose_from_matrix(bad), std::invalid_argument);
}

TEST(Geometry, SurfaceSamplesAreUniformOnTheSurface) {
  // Box 0.1 x 0.2 x 0.3: every sample on a face with that face's outward normal, and the fraction
  // of samples on each face pair equal to its area share.
  const double a = 0.1, b = 0.2, c = 0.3;
  const TriMesh m = box(a, b, c);
  EXPECT_NEAR(surface_area(m), 2 * (a * b + b * c + a * c), 1e-12);
  const int n = 20000;
  const SurfaceSamples s = sample_surface(m, n, 3);
  ASSERT_EQ(s.points.rows(), n);
  ASSERT_EQ(s.normals.rows(), n);
  const Vec3 extent(a, b, c);
  int top_bottom = 0;
  for (int i = 0; i < n; ++i) {
    const Vec3 p = s.points.row(i).transpose(), nrm = s.normals.row(i).transpose();
    EXPECT_NEAR(nrm.norm(), 1.0, 1e-12);
    int axis;
    nrm.cwiseAbs().maxCoeff(&axis);
    EXPECT_NEAR(std::abs(nrm[axis]), 1.0, 1e-12);
    EXPECT_NEAR(p[axis], nrm[axis] > 0 ? extent[axis] : 0.0, 1e-12);  // on the face the normal names
    EXPECT_TRUE((p.array() >= -1e-12).all() && (p.array() <= extent.array() + 1e-12).all());
    top_bottom += axis == 2;
  }
  EXPECT_NEAR(top_bottom / double(n), a * b / (a * b + b * c + a * c), 0.01);  // 3 sigma ~ 0.008
  const SurfaceSamples same = sample_surface(m, n, 3), other = sample_surface(m, n, 4);
  EXPECT_TRUE(s.points == same.points);  // seeded
  EXPECT_FALSE(s.points == other.points);
}

TEST(Geometry, SurfaceSamplingRejectsBadInput) {
  TriMesh flat;  // zero area
  flat.V.resize(3, 3);
  flat.V << 0, 0, 0, 1, 0, 0, 2, 0, 0;
  flat.F.resize(1, 3);
  flat.F << 0, 1, 2;
  EXPECT_EQ(surface_area(flat), 0.0);
  EXPECT_THROW(sample_surface(flat, 10, 0), std::invalid_argument);
  EXPECT_THROW(sample_surface(box(1, 1, 1), 0, 0), std::invalid_argument);
  EXPECT_THROW(sample_surface(TriMesh{}, 10, 0), std::invalid_argument);
}

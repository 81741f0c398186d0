// Tests of the vision concept: ray-cast depth against analytic depth, noise model, segmentation,
// registration of known transforms, bad inputs and determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bayesgrasp/vision/camera.hpp"
#include "bayesgrasp/vision/registration.hpp"
#include "bayesgrasp/vision/segmentation.hpp"

using namespace bayesgrasp;
using namespace bayesgrasp::vision;

namespace {
constexpr double kPi = 3.14159265358979323846;

// Prism over a planar polygon (CCW seen from +z) from z = 0 to z = h; cap triangles given.
TriMesh prism(const std::vector<Eigen::Vector2d>& poly, const std::vector<std::array<int, 3>>& cap, double h) {
  const int n = static_cast<int>(poly.size());
  TriMesh m;
  m.V.resize(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    m.V.row(i) << poly[i].x(), poly[i].y(), 0.0;
    m.V.row(n + i) << poly[i].x(), poly[i].y(), h;
  }
  std::vector<std::array<int, 3>> F;
  for (const auto& t : cap) {
    F.push_back({t[0], t[2], t[1]});              // bottom, facing -z
    F.push_back({n + t[0], n + t[1], n + t[2]});  // top, facing +z
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    F.push_back({i, j, n + j});
    F.push_back({i, n + j, n + i});
  }
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t f = 0; f < F.size(); ++f) m.F.row(static_cast<Eigen::Index>(f)) << F[f][0], F[f][1], F[f][2];
  return m;
}

TriMesh box(double a, double b, double c) {  // [-a/2, a/2] x [-b/2, b/2] x [0, c]
  return prism({{-a / 2, -b / 2}, {a / 2, -b / 2}, {a / 2, b / 2}, {-a / 2, b / 2}}, {{0, 1, 2}, {0, 2, 3}}, c);
}

// An L-shaped block (asymmetric): 12 x 4 cm foot plus a 4 x 10 cm leg, 6 cm tall.
TriMesh l_block() {
  return prism({{0, 0}, {0.12, 0}, {0.12, 0.04}, {0.04, 0.04}, {0.04, 0.10}, {0, 0.10}},
               {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}}, 0.06);
}

TriMesh uv_sphere(const Vec3& c, double r, int nu, int nv) {
  TriMesh m;
  m.V.resize(2 + (nv - 1) * nu, 3);
  m.V.row(0) = (c + Vec3(0, 0, r)).transpose();
  m.V.row(1) = (c - Vec3(0, 0, r)).transpose();
  for (int i = 1; i < nv; ++i)
    for (int j = 0; j < nu; ++j) {
      const double th = kPi * i / nv, ph = 2 * kPi * j / nu;
      m.V.row(2 + (i - 1) * nu + j) = (c + r * Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th))).transpose();
    }
  std::vector<std::array<int, 3>> F;
  auto id = [&](int i, int j) { return 2 + (i - 1) * nu + (j % nu); };
  for (int j = 0; j < nu; ++j) {
    F.push_back({0, id(1, j), id(1, j + 1)});
    F.push_back({1, id(nv - 1, j + 1), id(nv - 1, j)});
    for (int i = 1; i < nv - 1; ++i) {
      F.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      F.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t f = 0; f < F.size(); ++f) m.F.row(static_cast<Eigen::Index>(f)) << F[f][0], F[f][1], F[f][2];
  return m;
}

NoiseModel no_noise() {
  NoiseModel n;
  n.enabled = false;
  return n;
}

// Partial view of `mesh` placed at `T` (world), seen from `eye` towards the object.
Points view(const TriMesh& mesh, const Iso3& T, const Vec3& eye, const Vec3& target, bool noise, std::uint64_t seed) {
  Intrinsics K;
  NoiseModel nm;
  nm.enabled = noise;
  nm.seed = seed;
  const Iso3 cam = look_at(eye, target);
  const RenderResult r = render(K, cam, {transformed(mesh, T)}, Table{}, nm);
  return depth_to_points(K, r.depth, cam, true, false);
}
}  // namespace

TEST(VisionCamera, LookAtConvention) {
  const Iso3 T = look_at(Vec3(1, 0, 0.5), Vec3(0, 0, 0.5));
  EXPECT_TRUE(T.linear().col(2).isApprox(Vec3(-1, 0, 0)));  // forward
  EXPECT_TRUE(T.linear().col(1).isApprox(Vec3(0, 0, -1)));  // image down = world down
  EXPECT_TRUE(T.linear().col(0).isApprox(Vec3(0, 1, 0)));   // image right
  EXPECT_NEAR(T.linear().determinant(), 1.0, 1e-12);
  EXPECT_THROW(look_at(Vec3(0, 0, 1), Vec3(0, 0, 0)), std::invalid_argument);  // parallel to up
  EXPECT_THROW(look_at(Vec3(0, 0, 1), Vec3(0, 0, 1)), std::invalid_argument);
}

TEST(VisionCamera, PlaneDepthMatchesAnalytic) {
  // A large quad z = 0 seen from (0.3, -0.6, 0.8) looking at the origin; depth of pixel (u, v) is
  // z_c = -o_z / d_z with d = R ((u - cx)/fx, (v - cy)/fy, 1).
  TriMesh quad;
  quad.V.resize(4, 3);
  quad.V << -5, -5, 0, 5, -5, 0, 5, 5, 0, -5, 5, 0;
  quad.F.resize(2, 3);
  quad.F << 0, 1, 2, 0, 2, 3;
  Intrinsics K;
  const Iso3 cam = look_at(Vec3(0.3, -0.6, 0.8), Vec3::Zero());
  const RenderResult r = render(K, cam, {quad}, Table{}, no_noise());
  Table table;
  table.enabled = true;
  table.half_x = table.half_y = 5;
  const RenderResult rt = render(K, cam, std::vector<TriMesh>{}, table, no_noise());
  int n = 0;
  for (int v = 0; v < K.height; v += 7)
    for (int u = 0; u < K.width; u += 7) {
      const Vec3 d = cam.linear() * Vec3((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      if (d.z() >= 0) continue;
      const double z = -0.8 / d.z();
      ASSERT_NEAR(r.depth(v, u), z, 1e-9 * z);
      ASSERT_NEAR(rt.depth(v, u), z, 1e-9 * z);
      EXPECT_EQ(rt.label(v, u), -2);
      ++n;
    }
  EXPECT_GT(n, 5000);
  // The back-projected points lie on the plane.
  const Points P = depth_to_points(K, r.depth, cam, true, false);
  EXPECT_EQ(P.rows(), K.width * K.height);
  EXPECT_LT(P.col(2).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(VisionCamera, SphereDepthMatchesAnalytic) {
  const Vec3 c(0.05, 0.02, 0.1);
  const double rad = 0.1;
  const TriMesh s = uv_sphere(c, rad, 256, 128);
  Intrinsics K;
  const Vec3 eye(0.2, -0.7, 0.5);
  const Iso3 cam = look_at(eye, c);
  const RenderResult r = render(K, cam, {s}, Table{}, no_noise());
  int n = 0;
  double max_err = 0;
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const Vec3 d = cam.linear() * Vec3((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      // |eye + t d - c|^2 = r^2
      const double A = d.squaredNorm(), B = 2 * d.dot(eye - c), C = (eye - c).squaredNorm() - rad * rad;
      const double disc = B * B - 4 * A * C;
      const bool hit = disc > 0;
      // Away from the silhouette (where the tessellation differs from the sphere) compare depth:
      // disc / 4A = r^2 - b^2 with b the ray's distance from the centre; keep b < 0.95 r.
      if (hit && disc / (4 * A) > (1 - 0.95 * 0.95) * rad * rad) {
        const double t = (-B - std::sqrt(disc)) / (2 * A);
        ASSERT_FALSE(std::isnan(r.depth(v, u)));
        max_err = std::max(max_err, std::abs(r.depth(v, u) - t));
        ++n;
      } else if (!hit) {
        ASSERT_TRUE(std::isnan(r.depth(v, u)));
      }
    }
  EXPECT_GT(n, 8000);  // the sphere covers ~ pi (525 * 0.1 / 0.87)^2 = 11 400 pixels
  EXPECT_LT(max_err, 1e-4);  // chord error of the tessellation: r (1 - cos(pi/128)) = 3e-5 m
}

TEST(VisionCamera, NoiseModelStatistics) {
  // A plane facing the camera at 1.5 m: mean depth unbiased, spread ~ sigma(z) plus
  // quantisation (step z^2 s / (f B)), dropping only at the border (edges of the quad).
  TriMesh quad;
  quad.V.resize(4, 3);
  quad.V << -5, -5, 0, 5, -5, 0, 5, 5, 0, -5, 5, 0;
  quad.F.resize(2, 3);
  quad.F << 0, 1, 2, 0, 2, 3;
  Intrinsics K;
  const Iso3 cam = look_at(Vec3(0, 0, 1.5), Vec3(0, 0.001, 0), Vec3::UnitY());
  NoiseModel nm;
  nm.seed = 7;
  const RenderResult r = render(K, cam, {quad}, Table{}, nm);
  double s = 0, s2 = 0;
  int n = 0;
  for (int i = 0; i < r.depth.size(); ++i) {
    const double z = r.depth.data()[i];
    if (std::isnan(z)) continue;
    s += z;
    s2 += z * z;
    ++n;
  }
  EXPECT_EQ(n, K.width * K.height);
  const double mean = s / n, sd = std::sqrt(s2 / n - mean * mean);
  const double sigma = 0.0012 + 0.0019 * 1.1 * 1.1;
  const double step = 1.5 * 1.5 * 0.125 / (525 * 0.075);
  EXPECT_NEAR(mean, 1.5, 5e-4);
  EXPECT_NEAR(sd, std::sqrt(sigma * sigma + step * step / 12), 0.15 * sigma);
  // Same seed, same image; another seed, another image.
  const RenderResult r2 = render(K, cam, {quad}, Table{}, nm);
  EXPECT_TRUE(r.depth.cwiseEqual(r2.depth).all());
  nm.seed = 8;
  const RenderResult r3 = render(K, cam, {quad}, Table{}, nm);
  EXPECT_FALSE(r.depth.cwiseEqual(r3.depth).all());
}

TEST(VisionCamera, GrazingPixelsAreDropped) {
  // A plane seen at 85 degrees of incidence everywhere is dropped (max incidence 78 degrees).
  TriMesh quad;
  quad.V.resize(4, 3);
  quad.V << -50, -50, 0, 50, -50, 0, 50, 50, 0, -50, 50, 0;
  quad.F.resize(2, 3);
  quad.F << 0, 1, 2, 0, 2, 3;
  Intrinsics K;
  K.width = K.height = 3;
  K.cx = K.cy = 1;
  const double a = 85 * kPi / 180;
  const Iso3 cam = look_at(Vec3(0, 0, 1), Vec3(std::tan(a), 0, 0));
  NoiseModel nm;
  nm.edge_drop_prob = 0;
  const RenderResult r = render(K, cam, {quad}, Table{}, nm);
  EXPECT_FALSE(std::isnan(render(K, cam, {quad}, Table{}, no_noise()).depth(1, 1)));
  EXPECT_TRUE(std::isnan(r.depth(1, 1)));
}

TEST(VisionCamera, SeesNothing) {
  Intrinsics K;
  const Iso3 cam = look_at(Vec3(0, 0, 1), Vec3(0, 0.001, 2), Vec3::UnitY());  // looking up
  const RenderResult r = render(K, cam, {box(0.1, 0.1, 0.1)}, Table{}, NoiseModel{});
  EXPECT_EQ(depth_to_points(K, r.depth, cam, true, false).rows(), 0);
  const Points org = depth_to_points(K, r.depth, cam, true, true);
  EXPECT_EQ(org.rows(), K.width * K.height);
  EXPECT_TRUE(org.array().isNaN().all());
}

TEST(VisionSampling, AreaWeightedUniform) {
  // Box 0.1 x 0.2 x 0.3: the fraction of samples on each face pair equals its area share.
  const TriMesh b = box(0.1, 0.2, 0.3);
  EXPECT_NEAR(surface_area(b), 2 * (0.02 + 0.03 + 0.06), 1e-12);
  const SurfaceSamples s = sample_surface(b, 20000, 3);
  int top_bottom = 0;
  for (int i = 0; i < s.points.rows(); ++i) {
    if (std::abs(s.normals(i, 2)) > 0.5) ++top_bottom;
    EXPECT_NEAR(s.normals.row(i).norm(), 1.0, 1e-12);
  }
  EXPECT_NEAR(top_bottom / 20000.0, 0.02 / 0.11, 0.01);  // 3 sigma ~ 0.008
  const SurfaceSamples s2 = sample_surface(b, 20000, 3);
  EXPECT_TRUE(s.points.isApprox(s2.points));
  TriMesh flat;  // zero area
  flat.V.resize(3, 3);
  flat.V << 0, 0, 0, 1, 0, 0, 2, 0, 0;
  flat.F.resize(1, 3);
  flat.F << 0, 1, 2;
  EXPECT_THROW(sample_surface(flat, 10, 0), std::invalid_argument);
}

TEST(VisionSegmentation, TwoObjectsOnTable) {
  Intrinsics K;
  Table table;
  table.enabled = true;
  table.half_x = table.half_y = 0.6;
  const TriMesh a = transformed(box(0.06, 0.08, 0.12), planar_pose(0.12, 0.0, 0.3));
  const TriMesh b = transformed(l_block(), planar_pose(-0.15, 0.05, 1.0));
  const Iso3 cam = look_at(Vec3(0.0, -0.8, 0.6), Vec3(0, 0, 0.05));
  NoiseModel nm;
  nm.seed = 1;
  const RenderResult r = render(K, cam, {a, b}, table, nm);
  const Points P = depth_to_points(K, r.depth, cam, true, true);  // organised, NaNs inside
  const SegmentationResult seg = segment_table(P);
  EXPECT_NEAR(seg.plane(2), 1.0, 1e-3);
  EXPECT_NEAR(seg.plane(3), 0.0, 2e-3);
  ASSERT_EQ(seg.clusters.size(), 2u);
  // Each cluster's centroid lies over one object's footprint; the L block shows more pixels.
  for (const auto& cp : seg.cluster_points) {
    const Vec3 c = cp.colwise().mean().transpose();
    const bool on_a = (c.head<2>() - Eigen::Vector2d(0.12, 0.0)).norm() < 0.06;
    const bool on_b = (c.head<2>() - (planar_pose(-0.15, 0.05, 1.0) * Vec3(0.04, 0.04, 0)).head<2>()).norm() < 0.07;
    EXPECT_TRUE(on_a != on_b);
    EXPECT_GT(c.z(), 0.01);
  }
  // Labels from the renderer: every cluster point belongs to one object only.
  for (std::size_t k = 0; k < seg.clusters.size(); ++k) {
    int la = 0, lb = 0;
    for (int row : seg.clusters[k]) {
      const int l = r.label.data()[row];
      la += l == 0;
      lb += l == 1;
    }
    EXPECT_TRUE(la == 0 || lb == 0);
    EXPECT_GT(la + lb, 0.98 * seg.clusters[k].size());
  }
  EXPECT_THROW(segment_table(Points(0, 3)), std::invalid_argument);
}

TEST(VisionRegistration, RecoversKnownTransformOfAsymmetricBlock) {
  const TriMesh L = l_block();
  RegistrationParams p;
  p.seed = 5;
  p.restarts = 6;  // the block's flat faces give few distinctive FPFH matches: search longer
  const ModelCloud model = model_from_mesh(L, p, 11);
  struct Case {
    double x, y, yaw;
    Vec3 eye;
  };
  for (const Case& c : {Case{0.05, 0.02, 0.7, Vec3(0.4, -0.6, 0.55)}, Case{-0.1, 0.1, 2.5, Vec3(-0.5, -0.5, 0.6)},
                        Case{0.0, 0.0, -2.0, Vec3(0.1, 0.7, 0.5)}}) {
    const Iso3 T = planar_pose(c.x, c.y, c.yaw);
    const Points scene = view(L, T, c.eye, T * Vec3(0.05, 0.04, 0.03), true, 3);
    p.has_viewpoint = true;
    p.viewpoint = c.eye;
    const auto res = register_models(scene, {model}, p);
    ASSERT_EQ(res.size(), 1u);
    ASSERT_TRUE(res[0].success) << res[0].reason;
    const Iso3 E(res[0].transform);
    EXPECT_LT(rotation_error(E.linear(), T.linear()) * 180 / kPi, 5.0) << "yaw " << c.yaw;
    EXPECT_LT((E.translation() - T.translation()).norm(), 0.005) << "yaw " << c.yaw;
    EXPECT_GT(res[0].fitness, 0.9);
    EXPECT_LT(res[0].rmse, 0.004);
    EXPECT_NEAR(res[0].weight, 1.0, 1e-12);
  }
}

TEST(VisionRegistration, WeightsPreferTheRightModelAndSameSeedSameResult) {
  const TriMesh L = l_block();
  const TriMesh B = box(0.05, 0.05, 0.2);
  RegistrationParams p;
  p.seed = 2;
  const Iso3 T = planar_pose(0.02, -0.03, 0.4);
  const Vec3 eye(0.5, -0.5, 0.5);
  p.has_viewpoint = true;
  p.viewpoint = eye;
  const Points scene = view(L, T, eye, T * Vec3(0.05, 0.04, 0.03), true, 9);
  const std::vector<ModelCloud> models = {model_from_mesh(B, p, 1), model_from_mesh(L, p, 2)};
  const auto r1 = register_models(scene, models, p);
  const auto r2 = register_models(scene, models, p);
  ASSERT_TRUE(r1[1].success);
  EXPECT_GT(r1[1].weight, r1[0].weight);
  if (r1[0].success) EXPECT_LT(r1[1].delta, r1[0].delta);  // else its weight is 0
  EXPECT_NEAR(r1[0].weight + r1[1].weight, 1.0, 1e-12);
  for (int i = 0; i < 2; ++i) {
    EXPECT_TRUE(r1[i].transform == r2[i].transform);
    EXPECT_EQ(r1[i].fitness, r2[i].fitness);
  }
}

TEST(VisionRegistration, RotationErrorAboutSymmetryAxis) {
  const Mat3 A = Eigen::AngleAxisd(0.3, Vec3::UnitZ()).toRotationMatrix();
  const Mat3 B = Eigen::AngleAxisd(2.0, Vec3::UnitZ()).toRotationMatrix() * Eigen::AngleAxisd(0.1, Vec3::UnitX()).toRotationMatrix();
  EXPECT_NEAR(rotation_error(A, A), 0.0, 1e-7);
  EXPECT_NEAR(rotation_error(A, Eigen::AngleAxisd(1.3, Vec3::UnitZ()).toRotationMatrix()), 1.0, 1e-9);
  EXPECT_NEAR(rotation_error(A, B, Vec3::UnitZ()), 0.1, 1e-9);  // spin about z ignored
}

TEST(VisionRegistration, BadInputs) {
  RegistrationParams p;
  const ModelCloud m = model_from_mesh(box(0.1, 0.1, 0.1), p, 0);
  EXPECT_THROW(register_models(Points(0, 3), {m}, p), std::invalid_argument);
  Points nanpts = Points::Constant(10, 3, std::numeric_limits<double>::quiet_NaN());
  EXPECT_THROW(register_models(nanpts, {m}, p), std::invalid_argument);
  EXPECT_THROW(register_models(Points::Random(100, 3), {}, p), std::invalid_argument);
  // A handful of points: explicit failure with a reason.
  const Points few = Points::Random(10, 3) * 0.05;
  const auto r = register_models(few, {m}, p);
  EXPECT_FALSE(r[0].success);
  EXPECT_NE(r[0].reason.find("at least"), std::string::npos);
  EXPECT_TRUE(r[0].transform.isIdentity());
  // A model without surface: explicit failure for that model only.
  const Points scene = view(box(0.1, 0.1, 0.1), Iso3::Identity(), Vec3(0.4, -0.4, 0.4), Vec3(0, 0, 0.05), false, 0);
  const auto r2 = register_models(scene, {ModelCloud{}, m}, p);
  EXPECT_FALSE(r2[0].success);
  EXPECT_NE(r2[0].reason.find("no surface"), std::string::npos);
  EXPECT_TRUE(r2[1].success);
  EXPECT_EQ(r2[0].weight, 0.0);
  RegistrationParams bad = p;
  bad.voxel = -1;
  EXPECT_THROW(register_models(scene, {m}, bad), std::invalid_argument);
}

TEST(VisionRegistrar, ReusedAcrossScenesEqualsOneShot) {
  const TriMesh L = l_block();
  const TriMesh B = box(0.05, 0.05, 0.2);
  RegistrationParams p;
  const std::vector<ModelCloud> models = {model_from_mesh(B, p, 1), model_from_mesh(L, p, 2)};
  Registrar reg(p);
  EXPECT_EQ(reg.add_models(models), 0);
  ASSERT_EQ(reg.size(), 2);
  EXPECT_TRUE(reg.model_ok(0) && reg.model_ok(1));
  EXPECT_GT(reg.model_points(1), 100);
  struct Case {
    double x, y, yaw;
    Vec3 eye;
    std::uint64_t seed;
  };
  for (const Case& c : {Case{0.02, -0.03, 0.4, Vec3(0.5, -0.5, 0.5), 2}, Case{-0.05, 0.04, 2.2, Vec3(-0.4, -0.5, 0.6), 7},
                        Case{0.0, 0.0, -1.0, Vec3(0.2, 0.6, 0.5), 3}}) {
    const Iso3 T = planar_pose(c.x, c.y, c.yaw);
    const Points scene = view(L, T, c.eye, T * Vec3(0.05, 0.04, 0.03), true, c.seed);
    RegistrationParams q = p;
    q.seed = c.seed;
    q.has_viewpoint = true;
    q.viewpoint = c.eye;
    const auto one = register_models(scene, models, q);
    const auto all = reg.register_scene(scene, c.seed, c.eye);
    const auto only_l = reg.register_scene(scene, c.seed, c.eye, {1});
    ASSERT_EQ(all.size(), 2u);
    ASSERT_EQ(only_l.size(), 1u);
    for (int i = 0; i < 2; ++i) {
      EXPECT_EQ(all[i].success, one[i].success);
      EXPECT_TRUE(all[i].transform == one[i].transform) << "model " << i << " yaw " << c.yaw;
      EXPECT_EQ(all[i].fitness, one[i].fitness);
      EXPECT_EQ(all[i].delta, one[i].delta);
      EXPECT_EQ(all[i].weight, one[i].weight);
      EXPECT_EQ(all[i].ransac_iterations, one[i].ransac_iterations);
      // Only the scene's features are timed per call; the one-shot call adds the model's.
      EXPECT_GT(one[i].time_features, all[i].time_features - 1e-3);
    }
    // One model alone: the same fit, its weight normalised over itself.
    EXPECT_TRUE(only_l[0].transform == all[1].transform);
    EXPECT_EQ(only_l[0].delta, all[1].delta);
    EXPECT_NEAR(only_l[0].weight, 1.0, 1e-12);
    ASSERT_TRUE(all[1].success) << all[1].reason;
    const Iso3 E(all[1].transform);
    EXPECT_LT(rotation_error(E.linear(), T.linear()) * 180 / kPi, 5.0) << "yaw " << c.yaw;
    EXPECT_LT((E.translation() - T.translation()).norm(), 0.005) << "yaw " << c.yaw;
  }
}

TEST(VisionRegistrar, OwnFeaturesMatchPclsInQuality) {
  // Our normals + FPFH and PCL's (pcl_features) follow the same definitions: both recover the
  // block's pose.
  const TriMesh L = l_block();
  RegistrationParams p;
  p.restarts = 6;
  const ModelCloud m = model_from_mesh(L, p, 11);
  const Iso3 T = planar_pose(0.05, 0.02, 0.7);
  const Vec3 eye(0.4, -0.6, 0.55);
  const Points scene = view(L, T, eye, T * Vec3(0.05, 0.04, 0.03), true, 3);
  for (bool pcl : {false, true}) {
    RegistrationParams q = p;
    q.pcl_features = pcl;
    Registrar reg(q);
    reg.add_models({m});
    const auto r = reg.register_scene(scene, 5, eye);
    ASSERT_TRUE(r[0].success) << r[0].reason;
    const Iso3 E(r[0].transform);
    EXPECT_LT(rotation_error(E.linear(), T.linear()) * 180 / kPi, 5.0) << "pcl " << pcl;
    EXPECT_LT((E.translation() - T.translation()).norm(), 0.005) << "pcl " << pcl;
  }
}

TEST(VisionRegistrar, BadInputs) {
  RegistrationParams p;
  RegistrationParams bad = p;
  bad.voxel = 0;
  EXPECT_THROW(Registrar{bad}, std::invalid_argument);
  Registrar reg(p);
  const Points scene = view(box(0.1, 0.1, 0.1), Iso3::Identity(), Vec3(0.4, -0.4, 0.4), Vec3(0, 0, 0.05), false, 0);
  EXPECT_THROW(reg.register_scene(scene, 0), std::invalid_argument);  // no models yet
  Points nanpts = Points::Constant(10, 3, std::numeric_limits<double>::quiet_NaN());
  Points halfnan = model_from_mesh(box(0.1, 0.1, 0.1), p, 0).surface.points;
  halfnan(3, 1) = std::numeric_limits<double>::quiet_NaN();
  ModelCloud nanmodel{{halfnan, model_from_mesh(box(0.1, 0.1, 0.1), p, 0).surface.normals}};
  EXPECT_EQ(reg.add_models({model_from_mesh(box(0.1, 0.1, 0.1), p, 0), ModelCloud{}, nanmodel}), 0);
  EXPECT_EQ(reg.add_models({model_from_mesh(box(0.1, 0.1, 0.1), p, 4)}), 3);
  EXPECT_TRUE(reg.model_ok(0));
  EXPECT_FALSE(reg.model_ok(1));
  EXPECT_NE(reg.model_reason(1).find("no surface"), std::string::npos);
  EXPECT_FALSE(reg.model_ok(2));
  EXPECT_NE(reg.model_reason(2).find("NaN"), std::string::npos);
  EXPECT_THROW(reg.model_ok(4), std::invalid_argument);
  EXPECT_THROW(reg.register_scene(scene, 0, std::nullopt, {0, 4}), std::invalid_argument);
  EXPECT_THROW(reg.register_scene(scene, 0, std::nullopt, {-1}), std::invalid_argument);
  EXPECT_THROW(reg.register_scene(Points(0, 3), 0), std::invalid_argument);
  EXPECT_THROW(reg.register_scene(nanpts, 0), std::invalid_argument);
  EXPECT_THROW(reg.register_scene(scene, 0, Vec3(0, std::numeric_limits<double>::infinity(), 0)),
               std::invalid_argument);
  const auto r = reg.register_scene(scene, 0, Vec3(0.4, -0.4, 0.4));
  ASSERT_EQ(r.size(), 4u);
  EXPECT_TRUE(r[0].success) << r[0].reason;
  EXPECT_FALSE(r[1].success);
  EXPECT_NE(r[1].reason.find("no surface"), std::string::npos);
  EXPECT_TRUE(r[1].transform.isIdentity());
  EXPECT_EQ(r[1].weight, 0.0);
  EXPECT_FALSE(r[2].success);
  EXPECT_TRUE(r[3].success);
  EXPECT_NEAR(r[0].weight + r[3].weight, 1.0, 1e-12);
  // Too few scene points: every model fails with the reason.
  const auto few = reg.register_scene(Points::Random(10, 3) * 0.05, 0);
  for (const auto& x : few) EXPECT_NE(x.reason.find("at least"), std::string::npos);
}

TEST(VisionRegistrar, ThreadCountDoesNotChangeTheResult) {
  // The features are computed pair-once on one thread and once per pair end on several; the
  // RANSAC is seeded per model: the same result either way.
  const TriMesh L = l_block();
  const Iso3 T = planar_pose(0.01, 0.02, -0.6);
  const Vec3 eye(0.5, 0.4, 0.5);
  const Points scene = view(L, T, eye, T * Vec3(0.05, 0.04, 0.03), true, 4);
  std::vector<std::vector<RegistrationResult>> out;
  for (int threads : {1, 2}) {
    RegistrationParams p;
    p.threads = threads;
    Registrar reg(p);
    reg.add_models({model_from_mesh(L, p, 2), model_from_mesh(box(0.05, 0.05, 0.2), p, 1)});
    out.push_back(reg.register_scene(scene, 9, eye));
  }
  for (int i = 0; i < 2; ++i) {
    EXPECT_TRUE(out[0][i].transform == out[1][i].transform) << "model " << i;
    EXPECT_EQ(out[0][i].delta, out[1][i].delta);
    EXPECT_EQ(out[0][i].model_points, out[1][i].model_points);
  }
}

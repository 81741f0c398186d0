// Tests of the vision concept: ray-cast depth against analytic depth, noise model, segmentation,
// registration of known transforms, typed failures, options, bad inputs and determinism. The
// registration's steps against brute-force oracles: test_vision_steps.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
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

// The square [-h, h]^2 at z = 0, facing +z.
TriMesh square(double h) {
  TriMesh quad;
  quad.V.resize(4, 3);
  quad.V << -h, -h, 0, h, -h, 0, h, h, 0, -h, h, 0;
  quad.F.resize(2, 3);
  quad.F << 0, 1, 2, 0, 2, 3;
  return quad;
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
  const TriMesh quad = square(5);
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
  const TriMesh quad = square(5);
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
  const TriMesh quad = square(50);
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

// ---- registration
namespace {
constexpr double kSigma = 0.5 * 0.005;  // default weight_sigma x voxel

// The block seen from `eye` at planar pose T, noisy, seeded.
Points block_view(const Iso3& T, const Vec3& eye, std::uint64_t seed) {
  return view(l_block(), T, eye, T * Vec3(0.05, 0.04, 0.03), true, seed);
}

// n points along a vertical line at the centre of a voxel column, jittered by less than 1 mm.
Points needle(int n) {
  Points P(n, 3);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.0009, 0.0009);
  for (int i = 0; i < n; ++i) P.row(i) << 0.0025 + u(rng), 0.0025 + u(rng), 0.2 * i / n;
  return P;
}
}  // namespace

TEST(VisionRegistration, RecoversKnownTransformOfAsymmetricBlock) {
  RegistrationOptions o;
  o.ransac.restarts = 6;  // the block's flat faces give few distinctive FPFH matches: search longer
  const ModelCloud model = model_from_mesh(l_block(), o, 11);
  struct Case {
    double x, y, yaw;
    Vec3 eye;
  };
  for (const Case& c : {Case{0.05, 0.02, 0.7, Vec3(0.4, -0.6, 0.55)}, Case{-0.1, 0.1, 2.5, Vec3(-0.5, -0.5, 0.6)},
                        Case{0.0, 0.0, -2.0, Vec3(0.1, 0.7, 0.5)}}) {
    const Iso3 T = planar_pose(c.x, c.y, c.yaw);
    const auto res = register_models(block_view(T, c.eye, 3), {model}, o, 5, c.eye);
    ASSERT_EQ(res.size(), 1u);
    ASSERT_TRUE(res[0].success()) << res[0].reason;
    EXPECT_EQ(res[0].status, RegistrationStatus::Ok);
    const Iso3 E(res[0].transform);
    EXPECT_LT(rotation_error(E.linear(), T.linear()) * 180 / kPi, 5.0) << "yaw " << c.yaw;
    EXPECT_LT((E.translation() - T.translation()).norm(), 0.005) << "yaw " << c.yaw;
    EXPECT_GT(res[0].fitness, 0.9);
    EXPECT_LT(res[0].rmse, 0.004);
    EXPECT_NEAR(res[0].phi, std::exp(-res[0].delta * res[0].delta / (2 * kSigma * kSigma)), 1e-12);
    EXPECT_GT(res[0].up_cos, std::cos(5 * kPi / 180));
  }
}

TEST(VisionRegistration, PhiPrefersTheRightModelAndSameSeedSameResult) {
  RegistrationOptions o;
  const Iso3 T = planar_pose(0.02, -0.03, 0.4);
  const Vec3 eye(0.5, -0.5, 0.5);
  const Points scene = block_view(T, eye, 9);
  const std::vector<ModelCloud> models = {model_from_mesh(box(0.05, 0.05, 0.2), o, 1), model_from_mesh(l_block(), o, 2)};
  const auto r1 = register_models(scene, models, o, 2, eye);
  const auto r2 = register_models(scene, models, o, 2, eye);
  ASSERT_TRUE(r1[1].success());
  if (r1[0].success()) {  // else the belief gives it weight 0
    EXPECT_GT(r1[1].phi, r1[0].phi);
    EXPECT_LT(r1[1].delta, r1[0].delta);
  }
  for (int i = 0; i < 2; ++i) {
    EXPECT_TRUE(r1[i].transform == r2[i].transform);
    EXPECT_EQ(r1[i].fitness, r2[i].fitness);
    EXPECT_EQ(r1[i].phi, r2[i].phi);
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
  RegistrationOptions o;
  const ModelCloud m = model_from_mesh(box(0.1, 0.1, 0.1), o, 0);
  EXPECT_THROW(register_models(Points(0, 3), {m}, o), std::invalid_argument);
  Points nanpts = Points::Constant(10, 3, std::numeric_limits<double>::quiet_NaN());
  EXPECT_THROW(register_models(nanpts, {m}, o), std::invalid_argument);
  EXPECT_THROW(register_models(Points::Random(100, 3), {}, o), std::invalid_argument);
  RegistrationOptions bad = o;
  bad.voxel = -1;
  const Points scene = view(box(0.1, 0.1, 0.1), Iso3::Identity(), Vec3(0.4, -0.4, 0.4), Vec3(0, 0, 0.05), false, 0);
  EXPECT_THROW(register_models(scene, {m}, bad), std::invalid_argument);
  EXPECT_THROW(register_models(scene, {m}, o, 0, Vec3(0, std::nan(""), 0)), std::invalid_argument);
  TriMesh flat;  // zero area
  flat.V.resize(3, 3);
  flat.V << 0, 0, 0, 1, 0, 0, 2, 0, 0;
  flat.F.resize(1, 3);
  flat.F << 0, 1, 2;
  EXPECT_THROW(model_from_mesh(flat, o, 0), std::invalid_argument);
  EXPECT_THROW(model_from_mesh(box(0.1, 0.1, 0.1), bad, 0), std::invalid_argument);
}

TEST(VisionRegistration, TypedFailures) {
  RegistrationOptions o;
  const ModelCloud good = model_from_mesh(box(0.1, 0.1, 0.1), o, 0);
  const Points scene = view(box(0.1, 0.1, 0.1), Iso3::Identity(), Vec3(0.4, -0.4, 0.4), Vec3(0, 0, 0.05), false, 0);
  // A handful of scene points: every model fails alike, with the identity.
  const auto few = register_models(Points::Random(10, 3) * 0.05, {good}, o);
  EXPECT_EQ(few[0].status, RegistrationStatus::TooFewScenePoints);
  EXPECT_FALSE(few[0].success());
  EXPECT_NE(few[0].reason.find("at least"), std::string::npos);
  EXPECT_TRUE(few[0].transform.isIdentity());
  // Models that cannot be prepared fail alone: no surface, NaN, two points far apart (no normals).
  ModelCloud nan_model = good;
  nan_model.surface.points(3, 1) = std::numeric_limits<double>::quiet_NaN();
  ModelCloud two{{Points(2, 3), Points(2, 3)}};
  two.surface.points << 0, 0, 0, 0.1, 0, 0;
  two.surface.normals << 0, 0, 1, 0, 0, 1;
  const auto r = register_models(scene, {ModelCloud{}, nan_model, two, good}, o);
  EXPECT_EQ(r[0].status, RegistrationStatus::NoSurface);
  EXPECT_EQ(r[1].status, RegistrationStatus::InvalidModel);
  EXPECT_EQ(r[2].status, RegistrationStatus::TooFewModelPoints);
  EXPECT_EQ(r[2].model_points, 0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_FALSE(r[i].success());
    EXPECT_FALSE(r[i].reason.empty());
    EXPECT_TRUE(r[i].transform.isIdentity());
    EXPECT_EQ(r[i].phi, 0.0);
  }
  EXPECT_TRUE(r[3].success()) << r[3].reason;
  EXPECT_TRUE(r[3].reason.empty());
  // A vertical needle: every pair of its points is closer than 2 voxels horizontally, so the
  // 4-DOF RANSAC rejects every sample.
  const auto none = register_models(needle(400), {good}, o);
  EXPECT_GE(none[0].scene_points, o.min_scene_points);
  EXPECT_EQ(none[0].status, RegistrationStatus::NoHypothesis);
  EXPECT_GT(none[0].ransac_iterations, 0);
  EXPECT_TRUE(none[0].transform.isIdentity());
}

TEST(VisionRegistration, OptionsAreValidatedNamingTheField) {
  const auto field_named = [](RegistrationOptions o, const std::string& name) {
    try {
      validate(o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what()).rfind(name + ":", 0) == 0;
    }
    return false;
  };
  RegistrationOptions o;
  EXPECT_NO_THROW(validate(o));
  struct Bad {
    const char* name;
    void (*set)(RegistrationOptions&);
  };
  const Bad cases[] = {
      {"voxel", [](RegistrationOptions& x) { x.voxel = 0; }},
      {"voxel", [](RegistrationOptions& x) { x.voxel = std::numeric_limits<double>::infinity(); }},
      {"inlier_distance", [](RegistrationOptions& x) { x.inlier_distance = -1; }},
      {"weight_sigma", [](RegistrationOptions& x) { x.weight_sigma = std::nan(""); }},
      {"min_scene_points", [](RegistrationOptions& x) { x.min_scene_points = 0; }},
      {"model_samples", [](RegistrationOptions& x) { x.model_samples = -1; }},
      {"threads", [](RegistrationOptions& x) { x.threads = -2; }},
      {"features.normal_radius", [](RegistrationOptions& x) { x.features.normal_radius = 0; }},
      {"features.feature_radius", [](RegistrationOptions& x) { x.features.feature_radius = -5; }},
      {"correspondences.neighbours", [](RegistrationOptions& x) { x.correspondences.neighbours = 0; }},
      {"ransac.iterations", [](RegistrationOptions& x) { x.ransac.iterations = 0; }},
      {"ransac.min_iterations", [](RegistrationOptions& x) { x.ransac.min_iterations = -1; }},
      {"ransac.confidence", [](RegistrationOptions& x) { x.ransac.confidence = 1.0; }},
      {"ransac.edge_similarity", [](RegistrationOptions& x) { x.ransac.edge_similarity = 0.0; }},
      {"ransac.max_normal_angle", [](RegistrationOptions& x) { x.ransac.max_normal_angle = 0.0; }},
      {"ransac.restarts", [](RegistrationOptions& x) { x.ransac.restarts = 0; }},
      {"ransac.candidates", [](RegistrationOptions& x) { x.ransac.candidates = 0; }},
      {"ransac.hypotheses", [](RegistrationOptions& x) { x.ransac.hypotheses = 0; }},
      {"icp.distance", [](RegistrationOptions& x) { x.icp.distance = 0; }},
      {"icp.iterations", [](RegistrationOptions& x) { x.icp.iterations = -1; }},
      {"icp.tolerance", [](RegistrationOptions& x) { x.icp.tolerance = -1e-6; }},
      {"icp.coarse_points", [](RegistrationOptions& x) { x.icp.coarse_points = 0; }},
      {"icp.coarse_iterations", [](RegistrationOptions& x) { x.icp.coarse_iterations = -1; }},
      {"up_prior.up", [](RegistrationOptions& x) { x.up_prior.up = Vec3::Zero(); }},
      {"up_prior.up", [](RegistrationOptions& x) { x.up_prior.up = Vec3(0, std::nan(""), 1); }},
      {"up_prior.max_tilt", [](RegistrationOptions& x) { x.up_prior.max_tilt = 0; }},
      {"up_prior.weight", [](RegistrationOptions& x) { x.up_prior.weight = -1; }},
  };
  for (const Bad& b : cases) {
    RegistrationOptions x;
    b.set(x);
    EXPECT_TRUE(field_named(x, b.name)) << b.name;
    EXPECT_THROW(Registrar{x}, std::invalid_argument) << b.name;
  }
  // Without the prior a zero up is unused (the up cosine is then taken against +z).
  RegistrationOptions no_prior;
  no_prior.up_prior.enabled = false;
  no_prior.up_prior.up = Vec3::Zero();
  EXPECT_NO_THROW(validate(no_prior));
}

TEST(VisionRegistration, OptionsTakeEffect) {
  // Each step's options reach it: results change as the options predict.
  const Iso3 T = planar_pose(0.05, 0.02, 0.7);
  const Vec3 eye(0.4, -0.6, 0.55);
  const Points scene = block_view(T, eye, 3);
  RegistrationOptions base;
  base.ransac.restarts = 6;
  const ModelCloud m = model_from_mesh(l_block(), base, 11);
  const RegistrationResult ref = register_models(scene, {m}, base, 5, eye)[0];
  ASSERT_TRUE(ref.success()) << ref.reason;
  RegistrationOptions o = base;
  o.weight_sigma = 1.0;  // phi of the same fit with twice the sigma
  const RegistrationResult wide = register_models(scene, {m}, o, 5, eye)[0];
  EXPECT_EQ(wide.delta, ref.delta);
  EXPECT_NEAR(wide.phi, std::exp(-ref.delta * ref.delta / (2 * 4 * kSigma * kSigma)), 1e-12);
  o = base;
  o.ransac.restarts = 2;
  o.ransac.iterations = 7;
  o.ransac.min_iterations = 0;
  EXPECT_LE(register_models(scene, {m}, o, 5, eye)[0].ransac_iterations, 14);
  o = base;
  o.min_scene_points = ref.scene_points + 1;
  EXPECT_EQ(register_models(scene, {m}, o, 5, eye)[0].status, RegistrationStatus::TooFewScenePoints);
  o = base;
  o.model_samples = 300;
  EXPECT_EQ(model_from_mesh(l_block(), o, 11).surface.points.rows(), 300);
  o = base;
  o.voxel = 0.008;  // coarser: fewer downsampled points
  EXPECT_LT(register_models(scene, {m}, o, 5, eye)[0].scene_points, ref.scene_points);
  o = base;
  o.icp.iterations = 0;  // the coarse hypothesis unrefined
  EXPECT_FALSE(register_models(scene, {m}, o, 5, eye)[0].transform == ref.transform);
}

TEST(VisionRegistrar, ReusedAcrossScenesEqualsOneShot) {
  RegistrationOptions o;
  const std::vector<ModelCloud> models = {model_from_mesh(box(0.05, 0.05, 0.2), o, 1), model_from_mesh(l_block(), o, 2)};
  Registrar reg(o);
  EXPECT_EQ(reg.add_models(models), 0);
  ASSERT_EQ(reg.size(), 2);
  EXPECT_TRUE(reg.model_info(0).ok() && reg.model_info(1).ok());
  EXPECT_GT(reg.model_info(1).points, 100);
  struct Case {
    double x, y, yaw;
    Vec3 eye;
    std::uint64_t seed;
  };
  for (const Case& c : {Case{0.02, -0.03, 0.4, Vec3(0.5, -0.5, 0.5), 2}, Case{-0.05, 0.04, 2.2, Vec3(-0.4, -0.5, 0.6), 7},
                        Case{0.0, 0.0, -1.0, Vec3(0.2, 0.6, 0.5), 3}}) {
    const Iso3 T = planar_pose(c.x, c.y, c.yaw);
    const Points scene = block_view(T, c.eye, c.seed);
    const auto one = register_models(scene, models, o, c.seed, c.eye);
    const auto all = reg.register_scene(scene, c.seed, c.eye);
    const auto only_l = reg.register_scene(scene, c.seed, c.eye, {1});
    ASSERT_EQ(all.size(), 2u);
    ASSERT_EQ(only_l.size(), 1u);
    for (int i = 0; i < 2; ++i) {
      EXPECT_EQ(all[i].status, one[i].status);
      EXPECT_TRUE(all[i].transform == one[i].transform) << "model " << i << " yaw " << c.yaw;
      EXPECT_EQ(all[i].fitness, one[i].fitness);
      EXPECT_EQ(all[i].delta, one[i].delta);
      EXPECT_EQ(all[i].phi, one[i].phi);
      EXPECT_EQ(all[i].ransac_iterations, one[i].ransac_iterations);
      for (double t : {one[i].time_features, one[i].time_global, one[i].time_icp, all[i].time_features})
        EXPECT_TRUE(std::isfinite(t) && t >= 0);
    }
    // One model alone: the same fit.
    EXPECT_TRUE(only_l[0].transform == all[1].transform);
    EXPECT_EQ(only_l[0].delta, all[1].delta);
    EXPECT_EQ(only_l[0].phi, all[1].phi);
    ASSERT_TRUE(all[1].success()) << all[1].reason;
    const Iso3 E(all[1].transform);
    EXPECT_LT(rotation_error(E.linear(), T.linear()) * 180 / kPi, 5.0) << "yaw " << c.yaw;
    EXPECT_LT((E.translation() - T.translation()).norm(), 0.005) << "yaw " << c.yaw;
  }
}

TEST(VisionRegistrar, OwnFeaturesMatchPclsInQuality) {
  // Our normals + FPFH and PCL's follow the same definitions: both recover the block's pose.
  RegistrationOptions o;
  o.ransac.restarts = 6;
  const ModelCloud m = model_from_mesh(l_block(), o, 11);
  const Iso3 T = planar_pose(0.05, 0.02, 0.7);
  const Vec3 eye(0.4, -0.6, 0.55);
  const Points scene = block_view(T, eye, 3);
  for (FeatureEstimator estimator : {FeatureEstimator::Ours, FeatureEstimator::Pcl}) {
    RegistrationOptions q = o;
    q.features.estimator = estimator;
    Registrar reg(q);
    reg.add_models({m});
    const auto r = reg.register_scene(scene, 5, eye);
    const bool pcl = estimator == FeatureEstimator::Pcl;
    ASSERT_TRUE(r[0].success()) << r[0].reason;
    const Iso3 E(r[0].transform);
    EXPECT_LT(rotation_error(E.linear(), T.linear()) * 180 / kPi, 5.0) << "pcl " << pcl;
    EXPECT_LT((E.translation() - T.translation()).norm(), 0.005) << "pcl " << pcl;
  }
}

TEST(VisionRegistrar, BadInputs) {
  RegistrationOptions o;
  RegistrationOptions bad = o;
  bad.voxel = 0;
  EXPECT_THROW(Registrar{bad}, std::invalid_argument);
  Registrar reg(o);
  const Points scene = view(box(0.1, 0.1, 0.1), Iso3::Identity(), Vec3(0.4, -0.4, 0.4), Vec3(0, 0, 0.05), false, 0);
  EXPECT_THROW(reg.register_scene(scene, 0), std::invalid_argument);  // no models yet
  Points nanpts = Points::Constant(10, 3, std::numeric_limits<double>::quiet_NaN());
  Points halfnan = model_from_mesh(box(0.1, 0.1, 0.1), o, 0).surface.points;
  halfnan(3, 1) = std::numeric_limits<double>::quiet_NaN();
  ModelCloud nanmodel{{halfnan, model_from_mesh(box(0.1, 0.1, 0.1), o, 0).surface.normals}};
  EXPECT_EQ(reg.add_models({model_from_mesh(box(0.1, 0.1, 0.1), o, 0), ModelCloud{}, nanmodel}), 0);
  EXPECT_EQ(reg.add_models({model_from_mesh(box(0.1, 0.1, 0.1), o, 4)}), 3);
  EXPECT_TRUE(reg.model_info(0).ok());
  EXPECT_EQ(reg.model_info(1).status, RegistrationStatus::NoSurface);
  EXPECT_EQ(reg.model_info(2).status, RegistrationStatus::InvalidModel);
  EXPECT_THROW(reg.model_info(4), std::invalid_argument);
  EXPECT_THROW(reg.register_scene(scene, 0, std::nullopt, {0, 4}), std::invalid_argument);
  EXPECT_THROW(reg.register_scene(scene, 0, std::nullopt, {-1}), std::invalid_argument);
  EXPECT_THROW(reg.register_scene(scene, 0, std::nullopt, std::vector<int>{}), std::invalid_argument);
  EXPECT_THROW(reg.register_scene(Points(0, 3), 0), std::invalid_argument);
  EXPECT_THROW(reg.register_scene(nanpts, 0), std::invalid_argument);
  EXPECT_THROW(reg.register_scene(scene, 0, Vec3(0, std::numeric_limits<double>::infinity(), 0)),
               std::invalid_argument);
  const auto r = reg.register_scene(scene, 0, Vec3(0.4, -0.4, 0.4));
  ASSERT_EQ(r.size(), 4u);
  EXPECT_TRUE(r[0].success()) << r[0].reason;
  EXPECT_EQ(r[1].status, RegistrationStatus::NoSurface);
  EXPECT_TRUE(r[1].transform.isIdentity());
  EXPECT_EQ(r[1].phi, 0.0);
  EXPECT_EQ(r[2].status, RegistrationStatus::InvalidModel);
  EXPECT_TRUE(r[3].success());
  // Too few scene points: every model fails with the status.
  for (const auto& x : reg.register_scene(Points::Random(10, 3) * 0.05, 0))
    EXPECT_EQ(x.status, RegistrationStatus::TooFewScenePoints);
}

TEST(VisionRegistrar, ThreadCountDoesNotChangeTheResult) {
  // The features are computed pair-once on one thread and once per pair end on several; the
  // RANSAC is seeded per model: the same result either way (0 = all cores).
  const Iso3 T = planar_pose(0.01, 0.02, -0.6);
  const Vec3 eye(0.5, 0.4, 0.5);
  const Points scene = block_view(T, eye, 4);
  std::vector<std::vector<RegistrationResult>> out;
  for (int threads : {1, 2, 0}) {
    RegistrationOptions o;
    o.threads = threads;
    Registrar reg(o);
    reg.add_models({model_from_mesh(l_block(), o, 2), model_from_mesh(box(0.05, 0.05, 0.2), o, 1)});
    out.push_back(reg.register_scene(scene, 9, eye));
  }
  for (std::size_t t = 1; t < out.size(); ++t)
    for (int i = 0; i < 2; ++i) {
      EXPECT_TRUE(out[0][i].transform == out[t][i].transform) << "model " << i;
      EXPECT_EQ(out[0][i].delta, out[t][i].delta);
      EXPECT_EQ(out[0][i].model_points, out[t][i].model_points);
    }
}

// The registration's steps against independent oracles: the radius grid and the feature
// correspondences against brute force, the fit measures and phi against analytic distances, ICP
// against a known offset, the normal orientation rules.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "bayesgrasp/vision/correspondences.hpp"
#include "bayesgrasp/vision/fit.hpp"
#include "bayesgrasp/vision/icp.hpp"
#include "bayesgrasp/vision/radius_grid.hpp"

using namespace bayesgrasp;
using namespace bayesgrasp::vision;

namespace {
PointsF random_points(int n, float extent, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.f, extent);
  PointsF P(n);
  for (auto& p : P) p = Eigen::Vector3f(u(rng), u(rng), u(rng));
  return P;
}

// A square grid of samples on z = 0 with spacing h, normals +z.
DenseModel plane_model(int n, float h, double radius) {
  DenseModel m;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.samples.points.emplace_back(i * h, j * h, 0.f);
      m.samples.normals.emplace_back(0.f, 0.f, 1.f);
    }
  m.grid.build(m.samples.points, radius);
  return m;
}
}  // namespace

TEST(VisionSteps, RadiusGridMatchesBruteForce) {
  const PointsF P = random_points(3000, 0.1f, 1);
  const double r = 0.008;
  const RadiusGrid grid(P, r);
  const PointsF Q = random_points(300, 0.12f, 2);
  std::vector<int> got;
  for (const auto& qf : Q) {
    const Eigen::Vector3d q = qf.cast<double>() - Eigen::Vector3d::Constant(0.01);
    std::vector<int> want;
    int best = -1;
    double best_d = r;
    for (int i = 0; i < static_cast<int>(P.size()); ++i) {
      const double d = (P[i].cast<double>() - q).norm();
      if (d <= r - 1e-9) want.push_back(i);
      if (d < best_d - 1e-9) {
        best_d = d;
        best = i;
      }
    }
    grid.within(q, got);
    std::sort(got.begin(), got.end());
    // Every point clearly inside is found, nothing clearly outside is.
    for (int i : want) EXPECT_TRUE(std::binary_search(got.begin(), got.end(), i));
    for (int i : got) EXPECT_LE((P[i].cast<double>() - q).norm(), r + 1e-6);
    const int k = grid.nearest(q);
    if (best >= 0) {
      ASSERT_GE(k, 0);
      EXPECT_NEAR((P[k].cast<double>() - q).norm(), best_d, 1e-6);
    }
  }
  EXPECT_EQ(grid.nearest(Eigen::Vector3d(1, 1, 1)), -1);  // far outside
  EXPECT_EQ(grid.nearest(Eigen::Vector3d(std::nan(""), 0, 0)), -1);
}

TEST(VisionSteps, FitMeasuresOnAPlane) {
  // Scene points straight above samples at heights d_i: distance d_i exactly; tau cuts them off.
  const DenseModel m = plane_model(40, 0.001f, 0.006);
  const double tau = 0.003;
  const std::vector<double> heights = {0.0005, 0.001, 0.002, 0.004, 0.02};
  std::vector<Eigen::Vector3d> scene;
  for (std::size_t i = 0; i < heights.size(); ++i) scene.emplace_back(0.010 + 0.002 * i, 0.02, heights[i]);
  const Fit f = measure_fit(m, scene, Iso3::Identity(), tau);
  EXPECT_DOUBLE_EQ(f.fitness, 3.0 / 5.0);
  EXPECT_NEAR(f.rmse, std::sqrt((0.0005 * 0.0005 + 0.001 * 0.001 + 0.002 * 0.002) / 3), 1e-12);
  EXPECT_NEAR(f.delta, std::sqrt((0.0005 * 0.0005 + 0.001 * 0.001 + 0.002 * 0.002 + 2 * tau * tau) / 5), 1e-12);
  // The same points moved down by the transform lie on the plane.
  Iso3 T = Iso3::Identity();
  T.translation() = Vec3(0, 0, -0.001);
  EXPECT_NEAR(measure_fit(m, {scene[1]}, T, tau).delta, 0.0, 1e-8);  // the samples are floats
  EXPECT_DOUBLE_EQ(phi(0.0, 0.0025), 1.0);
  EXPECT_NEAR(phi(0.0025, 0.0025), std::exp(-0.5), 1e-15);
  // Up cosine and the selection cost's upside-down penalty.
  UpPrior prior;
  Iso3 flip = Iso3::Identity();
  flip.linear() = Eigen::AngleAxisd(3.14159265358979323846, Vec3::UnitX()).toRotationMatrix();
  EXPECT_NEAR(up_cosine(flip, Vec3::UnitZ()), -1.0, 1e-12);
  EXPECT_NEAR(selection_cost(f, flip, tau, Vec3::UnitZ(), prior), f.delta / tau + 1.0, 1e-12);
  prior.enabled = false;
  EXPECT_NEAR(selection_cost(f, flip, tau, Vec3::UnitZ(), prior), f.delta / tau, 1e-12);
}

TEST(VisionSteps, IcpRemovesAKnownOffsetAgainstAPlane) {
  // Point-to-plane ICP against a plane recovers the offset along its normal in one step.
  const DenseModel m = plane_model(60, 0.001f, 0.006);
  std::vector<Eigen::Vector3d> scene;
  for (int i = 5; i < 55; i += 3)
    for (int j = 5; j < 55; j += 3) scene.emplace_back(0.001 * i + 0.0003, 0.001 * j + 0.0002, 0.002);
  const Iso3 T = point_to_plane_icp(m, scene, Iso3::Identity(), 0.004, 10, 1e-9);
  EXPECT_NEAR(T.translation().z(), -0.002, 1e-9);
  EXPECT_LT(Eigen::AngleAxisd(T.linear()).angle(), 1e-9);
}

TEST(VisionSteps, CorrespondencesMatchBruteForce) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> u(0.f, 100.f);
  Features fs(40, 33), fm(25, 33);
  for (int i = 0; i < fs.size(); ++i) fs.data()[i] = u(rng);
  for (int i = 0; i < fm.size(); ++i) fm.data()[i] = u(rng);
  CorrespondenceOptions o;
  o.neighbours = 3;
  for (bool hellinger : {false, true}) {
    o.hellinger = hellinger;
    const MatchDescriptors s = match_descriptors(fs, hellinger), m = match_descriptors(fm, hellinger);
    const Correspondences c = correspondences(s, m, o);
    ASSERT_EQ(c.size(), 40u * 3 + 25);
    const auto dist = [&](int i, int j) {
      const Eigen::VectorXf a = hellinger ? Eigen::VectorXf(fs.row(i).transpose().cwiseSqrt()) : Eigen::VectorXf(fs.row(i).transpose());
      const Eigen::VectorXf b = hellinger ? Eigen::VectorXf(fm.row(j).transpose().cwiseSqrt()) : Eigen::VectorXf(fm.row(j).transpose());
      return (a - b).squaredNorm();
    };
    for (int i = 0; i < 40; ++i) {
      std::vector<int> order(25);
      std::iota(order.begin(), order.end(), 0);
      std::sort(order.begin(), order.end(), [&](int a, int b) { return dist(i, a) < dist(i, b); });
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(c[3 * i + k].first, i);
        EXPECT_EQ(c[3 * i + k].second, order[k]);
      }
    }
    for (int j = 0; j < 25; ++j) {  // reverse: each model descriptor's nearest scene descriptor
      int best = 0;
      for (int i = 1; i < 40; ++i)
        if (dist(i, j) < dist(best, j)) best = i;
      EXPECT_EQ(c[120 + j], std::make_pair(best, j));
    }
  }
  o.reverse = false;
  EXPECT_EQ(correspondences(match_descriptors(fs, true), match_descriptors(fm, true), o).size(), 40u * 3);
}

TEST(VisionSteps, NormalOrientationRules) {
  const Eigen::Vector3f n(0, 0, 1), p(0, 0, 0.1f), c(0, 0, 0.2f);
  EXPECT_EQ(orient(NormalOrientation::towards(Eigen::Vector3d(0, 0, -1)), n, p, n, c), -n);
  EXPECT_EQ(orient(NormalOrientation::towards(Eigen::Vector3d(0, 0, 1)), n, p, n, c), n);
  EXPECT_EQ(orient(NormalOrientation::along_reference(), n, p, -n, c), -n);
  EXPECT_EQ(orient(NormalOrientation::away_from_centroid(), n, p, n, c), -n);  // centroid above p
}

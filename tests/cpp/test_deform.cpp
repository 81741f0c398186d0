// Coherent Point Drift (deform/cpd.hpp) against oracles that follow from the construction: a
// copy of the model scaled, stretched or seen only in part, and the model itself.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "bayesgrasp/common/random.hpp"
#include "bayesgrasp/deform/cpd.hpp"

using namespace bayesgrasp;
using deform::CpdOptions;
using deform::Points;

namespace {

/// n points on an ellipsoid with semi-axes a, b, c (a mug-sized blob), seeded.
Points ellipsoid(int n, double a, double b, double c, std::uint64_t seed) {
  Rng rng(mix_seed(seed));
  Points P(n, 3);
  for (int i = 0; i < n; ++i) {
    const double z = 2.0 * uniform01(rng) - 1.0, t = 2.0 * M_PI * uniform01(rng), r = std::sqrt(1.0 - z * z);
    P.row(i) << a * r * std::cos(t), b * r * std::sin(t), c * z;
  }
  return P;
}

double rms_radius(const Points& P) {
  return std::sqrt((P.rowwise() - P.colwise().mean()).rowwise().squaredNorm().mean());
}

}  // namespace

TEST(Deform, TheModelOntoItselfBarelyMoves) {
  const Points Y = ellipsoid(300, 0.04, 0.05, 0.06, 1);
  const auto r = deform::coherent_point_drift(Y, Y);
  EXPECT_TRUE(r.converged);
  EXPECT_LT((r.moved - Y).rowwise().norm().maxCoeff(), 1e-3);
  EXPECT_LT(r.residual, 1e-3);
}

TEST(Deform, AScaledCopyIsRecoveredWithin2Percent) {
  const Points Y = ellipsoid(400, 0.04, 0.05, 0.06, 2);
  const Points X = ellipsoid(500, 0.044, 0.055, 0.066, 3);  // another sample of the 1.1x surface
  const auto r = deform::coherent_point_drift(Y, X);
  EXPECT_NEAR(rms_radius(r.moved) / rms_radius(Y), 1.1, 0.022);
  // the residual is bounded below by the two samplings' spacing: the true 1.1x model's is the reference
  const Points ideal = Y * 1.1;
  double s = 0.0;
  for (Eigen::Index n = 0; n < X.rows(); ++n) s += (ideal.rowwise() - X.row(n)).rowwise().squaredNorm().minCoeff();
  EXPECT_LT(r.residual, 1.1 * std::sqrt(s / double(X.rows())));
  // the field carries any point: the model's own points warped equal `moved`
  EXPECT_LT((r.field.warp(Y) - r.moved).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(Deform, AStretchIsFollowedPointByPoint) {
  const Points Y = ellipsoid(400, 0.04, 0.04, 0.06, 4);
  Points X = Y;
  X.col(0) *= 1.2;  // the same points, stretched along x: each model point's true image is known
  CpdOptions o;
  o.outlier_weight = 0.0;
  const auto r = deform::coherent_point_drift(Y, X, o);
  const double err = (r.moved - X).rowwise().norm().mean();
  EXPECT_LT(err, 0.002) << "mean error to the true images";
  EXPECT_NEAR((r.moved.col(0).maxCoeff() - r.moved.col(0).minCoeff()) / (Y.col(0).maxCoeff() - Y.col(0).minCoeff()),
              1.2, 0.024);
}

TEST(Deform, TheUnseenSideMovesWithTheSeenOne) {
  // only the +x half of the 1.1x copy is observed; coherence carries the -x half along
  const Points Y = ellipsoid(400, 0.04, 0.05, 0.06, 5);
  const Points full = ellipsoid(800, 0.044, 0.055, 0.066, 6);
  Points X(0, 3);
  for (Eigen::Index i = 0; i < full.rows(); ++i)
    if (full(i, 0) > 0.0) {
      X.conservativeResize(X.rows() + 1, 3);
      X.row(X.rows() - 1) = full.row(i);
    }
  const auto r = deform::coherent_point_drift(Y, X);
  double unseen = 0.0;
  int n = 0;
  for (Eigen::Index i = 0; i < Y.rows(); ++i)
    if (Y(i, 0) < -0.02) {
      unseen += r.moved.row(i).norm() / Y.row(i).norm();
      ++n;
    }
  EXPECT_NEAR(unseen / n, 1.1, 0.05) << "the hidden side grows with the seen side";
}

TEST(Deform, LowRankAgreesWithExact) {
  const Points Y = ellipsoid(300, 0.04, 0.05, 0.06, 7);
  const Points X = ellipsoid(400, 0.046, 0.05, 0.063, 8);
  CpdOptions exact, low;
  exact.rank = 0;
  low.rank = 60;
  const auto a = deform::coherent_point_drift(Y, X, exact), b = deform::coherent_point_drift(Y, X, low);
  EXPECT_LT((a.moved - b.moved).rowwise().norm().maxCoeff(), 0.002);
  EXPECT_EQ(b.field.landmarks.rows(), 60);
}

TEST(Deform, SameInputSameResultWhateverTheThreads) {
  const Points Y = ellipsoid(200, 0.04, 0.05, 0.06, 9), X = ellipsoid(300, 0.05, 0.05, 0.06, 10);
  CpdOptions one, all;
  one.threads = 1;
  const auto a = deform::coherent_point_drift(Y, X, one), b = deform::coherent_point_drift(Y, X, all);
  EXPECT_LT((a.moved - b.moved).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(Deform, BadInputIsNamed) {
  const Points Y = ellipsoid(50, 0.04, 0.05, 0.06, 11);
  EXPECT_THROW(deform::coherent_point_drift(Points(0, 3), Y), std::invalid_argument);
  Points nan = Y;
  nan(3, 1) = std::nan("");
  EXPECT_THROW(deform::coherent_point_drift(Y, nan), std::invalid_argument);
  EXPECT_THROW(deform::coherent_point_drift(Points::Zero(5, 3), Y), std::invalid_argument);  // one place
  CpdOptions o;
  o.outlier_weight = 1.0;
  try {
    deform::coherent_point_drift(Y, Y, o);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("outlier_weight"), std::string::npos);
  }
  o = CpdOptions{};
  o.beta = 0.0;
  EXPECT_THROW(deform::validate(o), std::invalid_argument);
}

TEST(Deform, FarthestPointsSpreadAndRepeatNothing) {
  const Points P = ellipsoid(100, 0.04, 0.05, 0.06, 12);
  const auto idx = deform::farthest_points(P, 10);
  ASSERT_EQ(idx.size(), 10u);
  EXPECT_EQ(idx[0], 0);
  EXPECT_EQ(std::set<int>(idx.begin(), idx.end()).size(), 10u);
  EXPECT_EQ(deform::farthest_points(Points::Zero(5, 3), 3).size(), 1u);  // copies of one point: one landmark
}

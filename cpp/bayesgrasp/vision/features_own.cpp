// Our normals and FPFH. The definitions are PCL's; the neighbours come from one fixed-radius grid
// search per point, shared by the normals and the features, and each point pair's features are
// computed once (single thread) or once per end (several threads, parallel over points): the
// results are the same either way.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>

#include "bayesgrasp/vision/features.hpp"

namespace bayesgrasp::vision {

namespace {

constexpr int kBins = 11;  // per pair feature; FPFH has 3 x kBins
using Counts = Eigen::Matrix<int, Eigen::Dynamic, 3 * kBins, Eigen::RowMajor>;
using Histograms = Eigen::Matrix<float, Eigen::Dynamic, 3 * kBins, Eigen::RowMajor>;

// Unit normal at point i by PCA over its neighbours within sqrt(rn2) (at least 3 points): the
// eigenvector of the neighbourhood covariance with the smallest eigenvalue, oriented. None if
// there are too few neighbours or the eigenvector is degenerate.
std::optional<Eigen::Vector3f> pca_normal(const OrientedCloud& down, int i, const std::vector<int>& nbr, float rn2,
                                          const NormalOrientation& orientation, const Eigen::Vector3f& centroid) {
  const Eigen::Vector3f& pi = down.points[i];
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int m = 0;
  for (int j : nbr) {
    const Eigen::Vector3f& pj = down.points[j];
    if ((pj - pi).squaredNorm() <= rn2) {
      mean += pj.cast<double>();
      ++m;
    }
  }
  if (m < 3) return std::nullopt;
  mean /= m;
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (int j : nbr) {
    const Eigen::Vector3f& pj = down.points[j];
    if ((pj - pi).squaredNorm() <= rn2) {
      const Eigen::Vector3d e = pj.cast<double>() - mean;
      C.noalias() += e * e.transpose();
    }
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(C);
  Eigen::Vector3f n = es.eigenvectors().col(0).cast<float>();  // eigenvalues ascending
  if (!n.allFinite() || n.norm() < 0.5f) return std::nullopt;
  n.normalize();
  return orient(orientation, n, pi, down.normals[i], centroid);
}

// The points that have a normal, renumbered, with the normals; id[i] = new index of point i or -1.
OrientedCloud keep_with_normals(const OrientedCloud& down, const std::vector<std::optional<Eigen::Vector3f>>& normal,
                                std::vector<int>& id) {
  OrientedCloud out;
  id.assign(down.points.size(), -1);
  for (std::size_t i = 0; i < down.points.size(); ++i) {
    if (!normal[i]) continue;
    id[i] = out.size();
    out.points.push_back(down.points[i]);
    out.normals.push_back(*normal[i]);
  }
  return out;
}

// Darboux-frame pair features of two oriented points (Rusu et al., "Fast Point Feature Histograms
// (FPFH) for 3D registration", ICRA 2009): the source is the point whose normal makes the smaller
// angle with the line joining them (|cos| larger; ties: the first argument), u = its normal,
// v = u x (pt - ps) / |pt - ps| normalised, w = u x v; f1 = atan2(w.nt, u.nt) in [-pi, pi],
// f2 = v.nt and f3 = u.(pt - ps)/|pt - ps| in [-1, 1]. Symmetric: pair(a, b) = pair(b, a) apart
// from ties, so the caller orders its arguments. Returns false for coincident points.
bool pair_features(const Eigen::Vector3f& pa, const Eigen::Vector3f& na, const Eigen::Vector3f& pb,
                   const Eigen::Vector3f& nb, float& f1, float& f2, float& f3) {
  Eigen::Vector3f dp = pb - pa;
  const float d = dp.norm();
  if (!(d > 0)) return false;
  dp /= d;
  const float ca = na.dot(dp), cb = nb.dot(dp);
  const Eigen::Vector3f *ns = &na, *nt = &nb;
  if (std::abs(ca) < std::abs(cb)) {  // b is the source; the line then points from b to a
    ns = &nb;
    nt = &na;
    dp = -dp;
    f3 = -cb;
  } else {
    f3 = ca;
  }
  Eigen::Vector3f v = ns->cross(dp);
  const float vn = v.norm();
  if (!(vn > 0)) return false;
  v /= vn;
  const Eigen::Vector3f w = ns->cross(v);
  f2 = v.dot(*nt);
  f1 = std::atan2(w.dot(*nt), ns->dot(*nt));
  return true;
}

// The three histogram bins of the pair (a, b), a < b; false for a degenerate pair.
bool pair_bins(const OrientedCloud& c, int a, int b, int* h) {
  constexpr float kTwoPi = 6.28318530717958647692f;
  float f1, f2, f3;
  if (!pair_features(c.points[a], c.normals[a], c.points[b], c.normals[b], f1, f2, f3)) return false;
  h[0] = std::clamp(static_cast<int>(std::floor(kBins * ((f1 + kTwoPi / 2) / kTwoPi))), 0, kBins - 1);
  h[1] = kBins + std::clamp(static_cast<int>(std::floor(kBins * ((f2 + 1.f) * 0.5f))), 0, kBins - 1);
  h[2] = 2 * kBins + std::clamp(static_cast<int>(std::floor(kBins * ((f3 + 1.f) * 0.5f))), 0, kBins - 1);
  return true;
}

// SPFH bin counts of every point over its feature neighbours fn.
Counts spfh_counts(const OrientedCloud& c, const std::vector<std::vector<int>>& fn, int threads) {
  const int n = c.size();
  Counts count = Counts::Zero(n, 3 * kBins);
  if (threads <= 1) {
    for (int i = 0; i < n; ++i)
      for (int j : fn[i]) {
        if (j < i) continue;  // each pair once
        int h[3];
        if (!pair_bins(c, i, j, h)) continue;
        for (int k = 0; k < 3; ++k) {
          ++count(i, h[k]);
          ++count(j, h[k]);
        }
      }
    return count;
  }
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int i = 0; i < n; ++i)
    for (int j : fn[i]) {
      int h[3];
      if (!pair_bins(c, std::min(i, j), std::max(i, j), h)) continue;
      for (int k = 0; k < 3; ++k) ++count(i, h[k]);
    }
  return count;
}

// FPFH(p) = sum over the neighbours q != p of SPFH(q) / |p - q|^2, each sub-histogram normalised
// to sum 100 (PCL's weighting, which leaves out p's own SPFH); SPFH(q) = q's counts scaled to sum
// 100 per sub-histogram.
Features fpfh(const Counts& count, const std::vector<std::vector<int>>& fn, const std::vector<std::vector<float>>& fd,
              int threads) {
  const int n = static_cast<int>(count.rows());
  Histograms spfh(n, 3 * kBins);
  for (int i = 0; i < n; ++i) {
    const float inc = fn[i].empty() ? 0.f : 100.f / static_cast<float>(fn[i].size());
    spfh.row(i) = count.row(i).cast<float>() * inc;
  }
  Features out = Features::Zero(n, 33);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<float, 1, 3 * kBins> acc = Eigen::Matrix<float, 1, 3 * kBins>::Zero();
    for (std::size_t k = 0; k < fn[i].size(); ++k)
      if (fd[i][k] > 0) acc += spfh.row(fn[i][k]) / fd[i][k];
    for (int s = 0; s < 3; ++s) {
      const float sum = acc.segment<kBins>(s * kBins).sum();
      if (sum > 0) acc.segment<kBins>(s * kBins) *= 100.f / sum;
    }
    out.row(i) = acc;
  }
  return out;
}

}  // namespace

Eigen::Vector3f centroid(const PointsF& points) {
  Eigen::Vector3f c = Eigen::Vector3f::Zero();
  for (const auto& p : points) c += p;
  if (!points.empty()) c /= static_cast<float>(points.size());
  return c;
}

FeatureCloud own_features(const OrientedCloud& down, double normal_radius, double feature_radius,
                          const NormalOrientation& orientation, int threads) {
  const int n0 = down.size();
  FeatureCloud out;
  if (n0 == 0) return out;
  // Neighbours within the larger radius, and the normals.
  const RadiusGrid grid(down.points, std::max(normal_radius, feature_radius));
  const float rn2 = static_cast<float>(normal_radius * normal_radius);
  const Eigen::Vector3f c = centroid(down.points);
  std::vector<std::vector<int>> nbr(n0);
  std::vector<std::optional<Eigen::Vector3f>> normal(n0);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int i = 0; i < n0; ++i) {
    grid.within(down.points[i].cast<double>(), nbr[i]);
    normal[i] = pca_normal(down, i, nbr[i], rn2, orientation, c);
  }
  std::vector<int> id;
  out.cloud = keep_with_normals(down, normal, id);
  const int n = out.cloud.size();
  if (n == 0) return out;
  // Feature neighbours among the kept points (self excluded), and their squared distances.
  const float rf2 = static_cast<float>(feature_radius * feature_radius);
  std::vector<std::vector<int>> fn(n);
  std::vector<std::vector<float>> fd(n);
  const PointsF& P = out.cloud.points;
  for (int i0 = 0; i0 < n0; ++i0) {
    const int i = id[i0];
    if (i < 0) continue;
    for (int j0 : nbr[i0]) {
      const int j = id[j0];
      if (j < 0 || j == i) continue;
      const float d2 = (P[j] - P[i]).squaredNorm();
      if (d2 <= rf2) {
        fn[i].push_back(j);
        fd[i].push_back(d2);
      }
    }
  }
  out.features = fpfh(spfh_counts(out.cloud, fn, threads), fn, fd, threads);
  return out;
}

FeatureCloud estimate_features(const OrientedCloud& down, const FeatureOptions& options, double voxel,
                               const NormalOrientation& orientation, int threads) {
  const double rn = options.normal_radius * voxel, rf = options.feature_radius * voxel;
  return options.estimator == FeatureEstimator::Pcl ? pcl_features(down, rn, rf, orientation, threads)
                                                     : own_features(down, rn, rf, orientation, threads);
}

}  // namespace bayesgrasp::vision

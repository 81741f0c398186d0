// Registration against object models. PCL provides the voxel downsampling (and, with
// pcl_features, its normal and FPFH estimators). Our normals and FPFH follow the same definitions
// but share one fixed-radius grid search between them and compute each point pair's features
// once, about 3x faster than PCL's estimators, which searched a k-d tree twice per point and
// computed every pair from both ends. The dense-model nearest neighbours of the fit measures and
// ICP come from a fixed-radius grid as well (their distances are cut off at the inlier/ICP
// distance), several times cheaper per query than the FLANN k-d tree. The RANSAC over feature
// correspondences and the point-to-plane ICP are ours so that they are seeded (PCL's
// SampleConsensusPrerejective draws from the global rand(), which is neither seedable per call
// nor deterministic under OpenMP) and so that the hypothesis choice can use the up prior.
// Everything about a model that does not depend on the scene is prepared once in a Registrar.
// All PCL templates are instantiated here, in our own flags, instead of using the instances
// precompiled into Debian's libpcl_*.so: with -march=native Eigen's heap alignment (and so its
// aligned_malloc/free) differs from the library's SSE2 build, and memory allocated on one side and
// freed on the other (e.g. point-cloud storage resized inside a filter) would corrupt the heap.
#define PCL_NO_PRECOMPILE
#include "bayesgrasp/vision/registration.hpp"

#include <omp.h>
#include <pcl/features/fpfh_omp.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
#include <random>
#include <mutex>
#include <shared_mutex>
#include <stdexcept>

namespace bayesgrasp::vision {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::uint64_t mix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

using CloudN = pcl::PointCloud<pcl::PointNormal>;
using Features = Eigen::Matrix<float, Eigen::Dynamic, 33, Eigen::RowMajor>;

// A cloud prepared for matching: downsampled points, normals and FPFH descriptors.
struct Prepared {
  CloudN::Ptr cloud;   // downsampled, with oriented normals (non-finite normals removed)
  Features features;   // one row per point of cloud
};

CloudN::Ptr to_cloud(const Points& P, const Points* N) {
  CloudN::Ptr c(new CloudN);
  c->reserve(P.rows());
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    if (!P.row(i).allFinite()) continue;
    pcl::PointNormal p;
    p.x = static_cast<float>(P(i, 0));
    p.y = static_cast<float>(P(i, 1));
    p.z = static_cast<float>(P(i, 2));
    if (N) {
      p.normal_x = static_cast<float>((*N)(i, 0));
      p.normal_y = static_cast<float>((*N)(i, 1));
      p.normal_z = static_cast<float>((*N)(i, 2));
    } else {
      p.normal_x = p.normal_y = p.normal_z = 0.f;
    }
    p.curvature = 0.f;
    c->push_back(p);
  }
  c->width = static_cast<std::uint32_t>(c->size());
  c->height = 1;
  c->is_dense = true;
  return c;
}

CloudN::Ptr downsample(const CloudN::Ptr& in, double voxel) {
  CloudN::Ptr out(new CloudN);
  pcl::VoxelGrid<pcl::PointNormal> vg;
  vg.setInputCloud(in);
  vg.setLeafSize(static_cast<float>(voxel), static_cast<float>(voxel), static_cast<float>(voxel));
  vg.filter(*out);  // averages xyz and the (reference) normals of each voxel
  return out;
}

// Exact nearest neighbour within a fixed radius among fixed points: a uniform grid with cells of
// at least the radius over the points' bounding box, points sorted by cell (counting sort); a
// query scans the 3 x 3 x 3 cells around its own, nearest cells first, skipping cells whose box is
// farther than the best distance so far. Much cheaper than a k-d tree for the short-range queries
// of the fit measures and ICP, whose distances are all cut off at the inlier / ICP distance.
class RadiusGrid {
 public:
  void build(const CloudN& cloud, double radius) {
    r2_ = radius * radius;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const auto& p : cloud) {
      lo = lo.cwiseMin(p.getVector3fMap().cast<double>());
      hi = hi.cwiseMax(p.getVector3fMap().cast<double>());
    }
    // Cell size: the radius, larger if the grid would have more than kMaxCells cells.
    constexpr double kMaxCells = 4.0e6;
    const Eigen::Vector3d ext = (hi - lo).cwiseMax(radius);
    h_ = std::max(radius, std::cbrt(ext.prod() / kMaxCells));
    origin_ = lo;
    for (int a = 0; a < 3; ++a) n_[a] = static_cast<int>(std::floor(ext[a] / h_)) + 1;
    const std::size_t cells = static_cast<std::size_t>(n_[0]) * n_[1] * n_[2];
    start_.assign(cells + 1, 0);
    std::vector<std::size_t> key(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      key[i] = cell_of(cloud[i].getVector3fMap().cast<double>());
      ++start_[key[i] + 1];
    }
    for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    xyz_.resize(3 * cloud.size());
    ids_.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const int j = fill[key[i]]++;
      ids_[j] = static_cast<int>(i);
      xyz_[3 * j] = cloud[i].x;
      xyz_[3 * j + 1] = cloud[i].y;
      xyz_[3 * j + 2] = cloud[i].z;
    }
  }

  // Indices of all points within the radius of q (distance <= radius), in cell order.
  void within(const Vec3& q, std::vector<int>& out) const {
    out.clear();
    int c[3];
    for (int a = 0; a < 3; ++a) {
      const double fl = std::floor((q[a] - origin_[a]) / h_);
      if (!(fl >= -1 && fl <= n_[a])) return;
      c[a] = static_cast<int>(fl);
    }
    const float qx = static_cast<float>(q.x()), qy = static_cast<float>(q.y()), qz = static_cast<float>(q.z());
    const float r2 = static_cast<float>(r2_);
    for (int z = std::max(0, c[2] - 1); z <= std::min(n_[2] - 1, c[2] + 1); ++z)
      for (int y = std::max(0, c[1] - 1); y <= std::min(n_[1] - 1, c[1] + 1); ++y)
        for (int x = std::max(0, c[0] - 1); x <= std::min(n_[0] - 1, c[0] + 1); ++x) {
          const std::size_t cell = (static_cast<std::size_t>(z) * n_[1] + y) * n_[0] + x;
          for (int j = start_[cell], e = start_[cell + 1]; j < e; ++j) {
            const float dx = xyz_[3 * j] - qx, dy = xyz_[3 * j + 1] - qy, dz = xyz_[3 * j + 2] - qz;
            if (dx * dx + dy * dy + dz * dz <= r2) out.push_back(ids_[j]);
          }
        }
  }

  // Index of the nearest point within the radius of q (ties: the first in cell order), -1 if none.
  int nearest(const Vec3& q) const {
    int c[3];
    Vec3 f;  // q's position inside its cell, in [0, 1) per axis when inside the grid
    for (int a = 0; a < 3; ++a) {
      const double u = (q[a] - origin_[a]) / h_;
      const double fl = std::floor(u);
      if (!(fl >= -1 && fl <= n_[a])) return -1;  // farther than one cell outside the grid (or NaN)
      c[a] = static_cast<int>(fl);
      f[a] = u - fl;
    }
    float best = static_cast<float>(r2_);
    int arg = -1;
    const float qx = static_cast<float>(q.x()), qy = static_cast<float>(q.y()), qz = static_cast<float>(q.z());
    // Own cell first, then the others ordered by how far their box is.
    static constexpr int kOrder[27][3] = {
        {0, 0, 0},   {-1, 0, 0},  {1, 0, 0},   {0, -1, 0},  {0, 1, 0},   {0, 0, -1},  {0, 0, 1},
        {-1, -1, 0}, {-1, 1, 0},  {1, -1, 0},  {1, 1, 0},   {-1, 0, -1}, {-1, 0, 1},  {1, 0, -1},
        {1, 0, 1},   {0, -1, -1}, {0, -1, 1},  {0, 1, -1},  {0, 1, 1},   {-1, -1, -1}, {-1, -1, 1},
        {-1, 1, -1}, {-1, 1, 1},  {1, -1, -1}, {1, -1, 1},  {1, 1, -1},  {1, 1, 1}};
    for (const auto& o : kOrder) {
      double box2 = 0;  // squared distance from q to the neighbour cell's box
      bool inside = true;
      for (int a = 0; a < 3; ++a) {
        const int ca = c[a] + o[a];
        if (ca < 0 || ca >= n_[a]) {
          inside = false;
          break;
        }
        const double g = o[a] < 0 ? f[a] * h_ : o[a] > 0 ? (1.0 - f[a]) * h_ : 0.0;
        box2 += g * g;
      }
      if (!inside || box2 >= best) continue;
      const std::size_t cell = (static_cast<std::size_t>(c[2] + o[2]) * n_[1] + (c[1] + o[1])) * n_[0] + (c[0] + o[0]);
      for (int j = start_[cell], e = start_[cell + 1]; j < e; ++j) {
        const float dx = xyz_[3 * j] - qx, dy = xyz_[3 * j + 1] - qy, dz = xyz_[3 * j + 2] - qz;
        const float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < best) {
          best = d2;
          arg = ids_[j];
        }
      }
    }
    return arg;
  }

 private:
  std::size_t cell_of(const Vec3& p) const {
    int c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(static_cast<int>(std::floor((p[a] - origin_[a]) / h_)), 0, n_[a] - 1);
    return (static_cast<std::size_t>(c[2]) * n_[1] + c[1]) * n_[0] + c[0];
  }
  double h_ = 1.0, r2_ = 0.0;
  Vec3 origin_ = Vec3::Zero();
  int n_[3] = {1, 1, 1};
  std::vector<int> start_;  // points of cell c: [start_[c], start_[c+1]) in xyz_ / ids_
  std::vector<float> xyz_;
  std::vector<int> ids_;
};

// Normals by PCA over a radius; oriented towards `viewpoint` (scene) or along the averaged
// reference normals carried by the points (model). Points without a normal are removed.
// Then FPFH over `feature_radius`.
enum class Orient { Viewpoint, Reference, AwayFromCentroid };
Prepared prepare_pcl(const CloudN::Ptr& down, double normal_radius, double feature_radius, Orient orient,
                 const Vec3& viewpoint, int threads) {
  CloudN::Ptr withn(new CloudN);
  pcl::NormalEstimationOMP<pcl::PointNormal, pcl::PointNormal> ne(threads);
  ne.setInputCloud(down);
  ne.setRadiusSearch(normal_radius);
  ne.setViewPoint(static_cast<float>(viewpoint.x()), static_cast<float>(viewpoint.y()),
                  static_cast<float>(viewpoint.z()));
  CloudN est;
  ne.compute(est);
  withn->reserve(down->size());
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  for (const auto& p : *down) centroid += p.getVector3fMap();
  if (!down->empty()) centroid /= static_cast<float>(down->size());
  for (std::size_t i = 0; i < down->size(); ++i) {
    pcl::PointNormal p = (*down)[i];
    Eigen::Vector3f n(est[i].normal_x, est[i].normal_y, est[i].normal_z);
    if (!n.allFinite() || n.norm() < 0.5f) continue;
    if (orient == Orient::Reference) {
      const Eigen::Vector3f ref(p.normal_x, p.normal_y, p.normal_z);
      if (n.dot(ref) < 0) n = -n;
    } else if (orient == Orient::AwayFromCentroid) {
      if (n.dot(p.getVector3fMap() - centroid) < 0) n = -n;
    }
    p.normal_x = n.x();
    p.normal_y = n.y();
    p.normal_z = n.z();
    p.curvature = est[i].curvature;
    withn->push_back(p);
  }
  withn->width = static_cast<std::uint32_t>(withn->size());
  withn->height = 1;
  Prepared out;
  out.cloud = withn;
  if (withn->empty()) return out;
  pcl::FPFHEstimationOMP<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> fe(threads);
  fe.setInputCloud(withn);
  fe.setInputNormals(withn);
  fe.setRadiusSearch(feature_radius);
  pcl::PointCloud<pcl::FPFHSignature33> f;
  fe.compute(f);
  out.features.resize(static_cast<Eigen::Index>(f.size()), 33);
  for (std::size_t i = 0; i < f.size(); ++i)
    for (int j = 0; j < 33; ++j) out.features(static_cast<Eigen::Index>(i), j) = f[i].histogram[j];
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

// Normals by PCA over `normal_radius` (at least 3 points; smallest-eigenvalue eigenvector of the
// neighbourhood covariance) oriented as `orient` says; points without a normal are removed. Then
// FPFH over `feature_radius`, 3 x 11 bins: SPFH(p) = histograms of (f1, f2, f3) over p's
// neighbours, each summing to 100; FPFH(p) = sum over the neighbours q != p of SPFH(q) / |p - q|^2,
// each sub-histogram normalised to sum 100 (PCL's weighting, which leaves out p's own SPFH).
// Neighbours come from one fixed-radius grid search per point, shared by normals and features;
// each pair's features are computed once (single thread) or once per end (threads > 1, parallel
// over points): the results are the same.
Prepared prepare(const CloudN::Ptr& down, double normal_radius, double feature_radius, Orient orient,
                 const Vec3& viewpoint, int threads) {
  const int n0 = static_cast<int>(down->size());
  Prepared out;
  out.cloud.reset(new CloudN);
  if (n0 == 0) return out;
  const double R = std::max(normal_radius, feature_radius);
  RadiusGrid grid;
  grid.build(*down, R);
  std::vector<std::vector<int>> nbr(n0);
  const float rn2 = static_cast<float>(normal_radius * normal_radius);
  const float rf2 = static_cast<float>(feature_radius * feature_radius);
  std::vector<Eigen::Vector3f> normal(n0);
  std::vector<char> valid(n0, 0);
  std::vector<float> curvature(n0, 0.f);
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  for (const auto& p : *down) centroid += p.getVector3fMap();
  centroid /= static_cast<float>(n0);
  const Eigen::Vector3f vp = viewpoint.cast<float>();
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int i = 0; i < n0; ++i) {
    const Eigen::Vector3f pi = (*down)[i].getVector3fMap();
    grid.within(pi.cast<double>(), nbr[i]);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    int m = 0;
    for (int j : nbr[i]) {
      const Eigen::Vector3f pj = (*down)[j].getVector3fMap();
      if ((pj - pi).squaredNorm() <= rn2) {
        mean += pj.cast<double>();
        ++m;
      }
    }
    if (m < 3) continue;
    mean /= m;
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (int j : nbr[i]) {
      const Eigen::Vector3f pj = (*down)[j].getVector3fMap();
      if ((pj - pi).squaredNorm() <= rn2) {
        const Eigen::Vector3d e = pj.cast<double>() - mean;
        C.noalias() += e * e.transpose();
      }
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    es.computeDirect(C);
    Eigen::Vector3f n = es.eigenvectors().col(0).cast<float>();  // eigenvalues ascending
    if (!n.allFinite() || n.norm() < 0.5f) continue;
    n.normalize();
    const auto& p = (*down)[i];
    if (orient == Orient::Reference) {
      if (n.dot(Eigen::Vector3f(p.normal_x, p.normal_y, p.normal_z)) < 0) n = -n;
    } else if (orient == Orient::AwayFromCentroid) {
      if (n.dot(pi - centroid) < 0) n = -n;
    } else if (n.dot(vp - pi) < 0) {
      n = -n;
    }
    const double tr = es.eigenvalues().sum();
    curvature[i] = tr > 0 ? static_cast<float>(es.eigenvalues()(0) / tr) : 0.f;
    normal[i] = n;
    valid[i] = 1;
  }
  // Keep the points with normals, renumbered.
  std::vector<int> id(n0, -1);
  for (int i = 0; i < n0; ++i) {
    if (!valid[i]) continue;
    id[i] = static_cast<int>(out.cloud->size());
    pcl::PointNormal p = (*down)[i];
    p.normal_x = normal[i].x();
    p.normal_y = normal[i].y();
    p.normal_z = normal[i].z();
    p.curvature = curvature[i];
    out.cloud->push_back(p);
  }
  out.cloud->width = static_cast<std::uint32_t>(out.cloud->size());
  out.cloud->height = 1;
  const int n = static_cast<int>(out.cloud->size());
  if (n == 0) return out;
  // Feature neighbours among the kept points (self excluded), and their squared distances.
  std::vector<std::vector<int>> fn(n);
  std::vector<std::vector<float>> fd(n);
  std::vector<Eigen::Vector3f> P(n), N(n);
  for (int i = 0; i < n; ++i) {
    P[i] = (*out.cloud)[i].getVector3fMap();
    N[i] = (*out.cloud)[i].getNormalVector3fMap();
  }
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
  // SPFH bin counts.
  constexpr int B = 11;
  constexpr float kTwoPi = 6.28318530717958647692f;
  Eigen::Matrix<int, Eigen::Dynamic, 3 * B, Eigen::RowMajor> count =
      Eigen::Matrix<int, Eigen::Dynamic, 3 * B, Eigen::RowMajor>::Zero(n, 3 * B);
  auto bins = [&](int a, int b, int* h) {  // a < b
    float f1, f2, f3;
    if (!pair_features(P[a], N[a], P[b], N[b], f1, f2, f3)) return false;
    h[0] = std::clamp(static_cast<int>(std::floor(B * ((f1 + kTwoPi / 2) / kTwoPi))), 0, B - 1);
    h[1] = B + std::clamp(static_cast<int>(std::floor(B * ((f2 + 1.f) * 0.5f))), 0, B - 1);
    h[2] = 2 * B + std::clamp(static_cast<int>(std::floor(B * ((f3 + 1.f) * 0.5f))), 0, B - 1);
    return true;
  };
  if (threads <= 1) {
    for (int i = 0; i < n; ++i)
      for (int j : fn[i]) {
        if (j < i) continue;  // each pair once
        int h[3];
        if (!bins(i, j, h)) continue;
        for (int k = 0; k < 3; ++k) {
          ++count(i, h[k]);
          ++count(j, h[k]);
        }
      }
  } else {
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int i = 0; i < n; ++i)
      for (int j : fn[i]) {
        int h[3];
        if (!bins(std::min(i, j), std::max(i, j), h)) continue;
        for (int k = 0; k < 3; ++k) ++count(i, h[k]);
      }
  }
  Eigen::Matrix<float, Eigen::Dynamic, 3 * B, Eigen::RowMajor> spfh(n, 3 * B);
  for (int i = 0; i < n; ++i) {
    const float inc = fn[i].empty() ? 0.f : 100.f / static_cast<float>(fn[i].size());
    spfh.row(i) = count.row(i).cast<float>() * inc;
  }
  out.features.setZero(n, 33);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<float, 1, 3 * B> acc = Eigen::Matrix<float, 1, 3 * B>::Zero();
    for (std::size_t k = 0; k < fn[i].size(); ++k)
      if (fd[i][k] > 0) acc += spfh.row(fn[i][k]) / fd[i][k];
    for (int s = 0; s < 3; ++s) {
      const float sum = acc.segment<B>(s * B).sum();
      if (sum > 0) acc.segment<B>(s * B) *= 100.f / sum;
    }
    out.features.row(i) = acc;
  }
  return out;
}

struct Hypothesis {
  Iso3 T = Iso3::Identity();  // scene -> model
  int inliers = 0;
  double cost = 0.0;
};

bool similar(const Iso3& a, const Iso3& b, double trans_tol, double rot_tol) {
  const double ang = Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
  return ang < rot_tol && (a.translation() - b.translation()).norm() < trans_tol;
}

// Rigid transform (no scale) taking src points onto dst points in the least-squares sense.
Iso3 kabsch(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst) {
  const Vec3 cs = src.rowwise().mean(), cd = dst.rowwise().mean();
  const Mat3 Hm = (src.colwise() - cs) * (dst.colwise() - cd).transpose();
  Eigen::JacobiSVD<Mat3> svd(Hm, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0) D(2, 2) = -1;
  Iso3 T = Iso3::Identity();
  T.linear() = svd.matrixV() * D * svd.matrixU().transpose();
  T.translation() = cd - T.linear() * cs;
  return T;
}

// A model prepared for registration: everything that does not depend on the scene.
struct ModelData {
  bool ok = false;
  std::string reason;
  CloudN::Ptr dense;  // all surface samples with exact normals
  RadiusGrid dense_grid;  // over the dense samples, radius max(inlier, ICP distance)
  Prepared prep;            // downsampled, normals, FPFH
  Features mfeat;           // the features as matched (square roots for the Hellinger distance)
  Eigen::VectorXf mf_norm;  // their squared norms
  std::vector<Vec3> mpts, mnrm;  // downsampled points and normals
  int nm = 0;
  double time = 0.0;        // s spent preparing
};

// The scene's part of a registration.
struct SceneData {
  int ns = 0;
  std::vector<Vec3> spts, snrm;
  Features sfeat;
  Eigen::VectorXf sf_norm;
  double time = 0.0;
};

// Distances from each (transformed) scene point to the nearest dense model sample within the
// grid's radius (infinity beyond; the fit measures and ICP cut distances off below it).
void nearest(const ModelData& m, const std::vector<Vec3>& pts, const Iso3& T, std::vector<double>& d,
             std::vector<int>& idx) {
  d.resize(pts.size());
  idx.resize(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Vec3 q = T * pts[i];
    const int k = m.dense_grid.nearest(q);
    idx[i] = k;
    if (k >= 0) {
      const auto& s = (*m.dense)[k];
      d[i] = (q - Vec3(s.x, s.y, s.z)).norm();
    } else {
      d[i] = std::numeric_limits<double>::infinity();
    }
  }
}

struct Fit {
  double fitness = 0, rmse = 0, delta = 0;
};
Fit measure(const ModelData& m, const std::vector<Vec3>& pts, const Iso3& T, double tau) {
  std::vector<double> d;
  std::vector<int> idx;
  nearest(m, pts, T, d, idx);
  Fit f;
  int n_in = 0;
  double s_in = 0, s_all = 0;
  for (double di : d) {
    if (di < tau) {
      ++n_in;
      s_in += di * di;
    }
    const double c = std::min(di, tau);
    s_all += c * c;
  }
  f.fitness = pts.empty() ? 0.0 : static_cast<double>(n_in) / pts.size();
  f.rmse = n_in ? std::sqrt(s_in / n_in) : 0.0;
  f.delta = pts.empty() ? tau : std::sqrt(s_all / pts.size());
  return f;
}

// Point-to-plane ICP, scene -> model, against the dense samples and their exact normals.
Iso3 icp(const ModelData& m, const std::vector<Vec3>& pts, Iso3 T, double max_dist, int iters, double tol) {
  std::vector<double> d;
  std::vector<int> idx;
  for (int it = 0; it < iters; ++it) {
    nearest(m, pts, T, d, idx);
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    int n = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (!(d[i] < max_dist)) continue;
      const auto& s = (*m.dense)[idx[i]];
      const Vec3 q = T * pts[i];
      const Vec3 nn(s.normal_x, s.normal_y, s.normal_z);
      const double r = (q - Vec3(s.x, s.y, s.z)).dot(nn);
      Eigen::Matrix<double, 6, 1> J;
      J.head<3>() = q.cross(nn);
      J.tail<3>() = nn;
      A.noalias() += J * J.transpose();
      b.noalias() -= J * r;
      ++n;
    }
    if (n < 6) break;
    A.diagonal().array() += 1e-9;
    const Eigen::Matrix<double, 6, 1> x = A.ldlt().solve(b);
    if (!x.allFinite()) break;
    Iso3 dT = Iso3::Identity();
    const double ang = x.head<3>().norm();
    if (ang > 0) dT.linear() = Eigen::AngleAxisd(ang, x.head<3>() / ang).toRotationMatrix();
    dT.translation() = x.tail<3>();
    T = dT * T;
    if (ang < tol && x.tail<3>().norm() < tol) break;
  }
  return T;
}

void validate(const RegistrationParams& P) {
  if (!(P.voxel > 0) || !std::isfinite(P.voxel)) throw std::invalid_argument("voxel must be positive and finite");
  for (double f : {P.normal_radius, P.feature_radius, P.inlier_distance, P.icp_distance, P.weight_sigma})
    if (!(f > 0) || !std::isfinite(f)) throw std::invalid_argument("radius and distance factors must be positive");
  if (P.ransac_iterations < 1 || P.restarts < 1 || P.hypotheses < 1 || P.candidates < 1 || P.coarse_points < 1 ||
      P.icp_iterations < 0 || P.coarse_icp_iterations < 0 || P.feature_neighbours < 1)
    throw std::invalid_argument("iteration, restart, hypothesis and neighbour counts must be positive");
  if (!(P.ransac_confidence > 0 && P.ransac_confidence < 1)) throw std::invalid_argument("ransac_confidence must be in (0, 1)");
  if (!(P.edge_similarity > 0 && P.edge_similarity < 1)) throw std::invalid_argument("edge_similarity must be in (0, 1)");
  if (P.use_up_prior && !(P.up.norm() > 0)) throw std::invalid_argument("up must be a non-zero vector");
}

// Model preparation: dense k-d tree, downsampling, normals along the samples' normals, FPFH.
void prepare_model(const SurfaceSamples& S, const RegistrationParams& P, ModelData& md) {
  const auto t0 = Clock::now();
  if (S.points.rows() == 0 || S.points.rows() != S.normals.rows()) {
    md.reason = "model has no surface points";
    return;
  }
  if (!S.points.allFinite() || !S.normals.allFinite()) {
    md.reason = "model points or normals contain NaN or infinity";
    return;
  }
  const double voxel = P.voxel;
  md.dense = to_cloud(S.points, &S.normals);
  md.dense_grid.build(*md.dense, std::max(P.inlier_distance, P.icp_distance) * voxel);
  CloudN::Ptr mdown = downsample(md.dense, voxel);
  md.prep = (P.pcl_features ? prepare_pcl : prepare)(mdown, P.normal_radius * voxel, P.feature_radius * voxel, Orient::Reference, Vec3::Zero(), 1);
  md.nm = static_cast<int>(md.prep.cloud->size());
  if (md.nm < 3) {
    md.reason = "model has too few points after downsampling (" + std::to_string(md.nm) + ")";
    md.time = seconds_since(t0);
    return;
  }
  md.mfeat = md.prep.features;
  if (P.hellinger) md.mfeat = md.mfeat.cwiseMax(0.f).cwiseSqrt();
  md.mf_norm = md.mfeat.rowwise().squaredNorm();
  md.mpts.resize(md.nm);
  md.mnrm.resize(md.nm);
  for (int i = 0; i < md.nm; ++i) {
    md.mpts[i] = (*md.prep.cloud)[i].getVector3fMap().cast<double>();
    md.mnrm[i] = (*md.prep.cloud)[i].getNormalVector3fMap().cast<double>();
  }
  md.ok = true;
  md.time = seconds_since(t0);
}

// Scene preparation: downsampling, normals towards the viewpoint (or away from the centroid), FPFH.
SceneData prepare_scene(const CloudN::Ptr& raw, const RegistrationParams& P, const std::optional<Vec3>& viewpoint,
                        int nthreads) {
  const auto t0 = Clock::now();
  const double voxel = P.voxel;
  CloudN::Ptr sdown = downsample(raw, voxel);
  const Prepared sprep = (P.pcl_features ? prepare_pcl : prepare)(sdown, P.normal_radius * voxel, P.feature_radius * voxel,
                                 viewpoint ? Orient::Viewpoint : Orient::AwayFromCentroid,
                                 viewpoint ? *viewpoint : Vec3::Zero(), nthreads);
  SceneData sd;
  sd.ns = static_cast<int>(sprep.cloud->size());
  sd.spts.resize(sd.ns);
  sd.snrm.resize(sd.ns);
  for (int i = 0; i < sd.ns; ++i) {
    sd.spts[i] = (*sprep.cloud)[i].getVector3fMap().cast<double>();
    sd.snrm[i] = (*sprep.cloud)[i].getNormalVector3fMap().cast<double>();
  }
  sd.sfeat = sprep.features;
  if (P.hellinger) sd.sfeat = sd.sfeat.cwiseMax(0.f).cwiseSqrt();  // Hellinger: L2 between sqrt histograms
  sd.sf_norm = sd.sfeat.rowwise().squaredNorm();
  sd.time = seconds_since(t0);
  return sd;
}

// Registers one prepared model against the prepared scene.
void register_one(const ModelData& md, const SceneData& sd, const RegistrationParams& P, std::uint64_t seed,
                  RegistrationResult& res) {
  const int ns = sd.ns, nm = md.nm;
  const std::vector<Vec3>& spts = sd.spts;
  const std::vector<Vec3>& snrm = sd.snrm;
  const Features& sfeat = sd.sfeat;
  const Eigen::VectorXf& sf_norm = sd.sf_norm;
  const double voxel = P.voxel, tau = P.inlier_distance * voxel;
  const Vec3 up = P.up.norm() > 0 ? P.up.normalized() : Vec3::UnitZ();
  const double cos_tilt = std::cos(P.max_tilt);
  // Rotation taking the scene's up onto +z (the model's up), for the 4-DOF hypotheses.
  const Mat3 R0 = Eigen::Quaterniond::FromTwoVectors(up, Vec3::UnitZ()).toRotationMatrix();
  // ---- correspondences: each scene feature's k nearest model features (brute force, L2).
  auto t0 = Clock::now();
  const int k = std::min(P.feature_neighbours, nm);
  const Features& mfeat = md.mfeat;
  const Eigen::VectorXf& mf_norm = md.mf_norm;
  std::vector<std::pair<int, int>> corr;
  corr.reserve(static_cast<std::size_t>(ns) * k + nm);
  {
    // Forward: each scene feature's k nearest model features. Reverse (optional): each model
    // feature's nearest scene feature, which keeps the matches spread over the model when many
    // scene features share a few nearest model features ("hubs", e.g. on flat faces).
    const int block = 256;
    Eigen::MatrixXf D;
    std::vector<int> top_i(k);
    std::vector<float> top_d(k);
    std::vector<float> rbest(nm, std::numeric_limits<float>::infinity());
    std::vector<int> rarg(nm, -1);
    for (int s0 = 0; s0 < ns; s0 += block) {
      const int bs = std::min(block, ns - s0);
      // Column i: -2 <model features, scene feature s0 + i>, contiguous for the scans below.
      D.noalias() = -2.0f * mfeat * sfeat.middleRows(s0, bs).transpose();
      for (int i = 0; i < bs; ++i) {
        const float* col = D.col(i).data();
        const float sn = sf_norm(s0 + i);
        // k nearest by one scan, kept sorted (ties: the lower index first).
        int cnt = 0;
        for (int j = 0; j < nm; ++j) {
          const float dj = col[j] + mf_norm(j);
          if (cnt < k || dj < top_d[cnt - 1]) {
            int pos = cnt < k ? cnt++ : k - 1;
            while (pos > 0 && top_d[pos - 1] > dj) {
              top_d[pos] = top_d[pos - 1];
              top_i[pos] = top_i[pos - 1];
              --pos;
            }
            top_d[pos] = dj;
            top_i[pos] = j;
          }
          if (P.reverse_matches && col[j] + sn < rbest[j]) {
            rbest[j] = col[j] + sn;
            rarg[j] = s0 + i;
          }
        }
        for (int j = 0; j < cnt; ++j) corr.emplace_back(s0 + i, top_i[j]);
      }
    }
    if (P.reverse_matches)
      for (int j = 0; j < nm; ++j)
        if (rarg[j] >= 0) corr.emplace_back(rarg[j], j);
  }
  const int nc = static_cast<int>(corr.size());
  const std::vector<Vec3>& mpts = md.mpts;

  // ---- RANSAC over correspondences, several restarts; keep distinct good hypotheses.
  const std::vector<Vec3>& mnrm = md.mnrm;
  std::vector<Hypothesis> hyps;
  const double tau2 = tau * tau;
  const double min_edge = 2.0 * voxel;
  const double sim = P.edge_similarity;
  const double cos_normal = std::cos(P.max_normal_angle);
  const bool four_dof = P.use_up_prior && P.upright;
  const int sample_size = four_dof ? 2 : 3;
  for (int rs = 0; rs < P.restarts; ++rs) {
    std::mt19937_64 rng(mix(seed * 0x100000001B3ull + static_cast<std::uint64_t>(rs)));
    std::uniform_int_distribution<int> pick(0, nc - 1);
    std::vector<Hypothesis> top;  // best distinct hypotheses of this restart
    int best = 0;
    long needed = P.ransac_iterations;
    int it = 0;
    for (; it < P.ransac_iterations && it < needed; ++it) {
      int s_id[3], m_id[3];
      for (int j = 0; j < sample_size; ++j) {
        const int c = pick(rng);
        s_id[j] = corr[c].first;
        m_id[j] = corr[c].second;
      }
      if (s_id[0] == s_id[1] || (sample_size == 3 && (s_id[0] == s_id[2] || s_id[1] == s_id[2]))) continue;
      Iso3 T = Iso3::Identity();
      bool okay = true;
      if (four_dof) {
        // Yaw about the up axis and a translation from two correspondences (the model's +z is
        // the scene's up): levelled scene points q = R0 p, then a rotation about z.
        const Vec3 qa = R0 * spts[s_id[0]], qb = R0 * spts[s_id[1]];
        const Vec3 dq = qb - qa, dm = mpts[m_id[1]] - mpts[m_id[0]];
        const double lq = dq.head<2>().norm(), lm = dm.head<2>().norm();
        if (lq < min_edge || lm < min_edge || std::min(lq, lm) < sim * std::max(lq, lm) ||
            std::abs(dq.z() - dm.z()) > tau)
          continue;
        const double yaw = std::atan2(dm.y(), dm.x()) - std::atan2(dq.y(), dq.x());
        T.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix() * R0;
        T.translation() = 0.5 * (mpts[m_id[0]] + mpts[m_id[1]]) - T.linear() * 0.5 * (spts[s_id[0]] + spts[s_id[1]]);
      } else {
        const int pairs[3][2] = {{0, 1}, {1, 2}, {0, 2}};
        for (const auto& pr : pairs) {
          const double ls = (spts[s_id[pr[0]]] - spts[s_id[pr[1]]]).norm();
          const double lm = (mpts[m_id[pr[0]]] - mpts[m_id[pr[1]]]).norm();
          if (ls < min_edge || lm < min_edge || std::min(ls, lm) < sim * std::max(ls, lm)) {
            okay = false;
            break;
          }
        }
        if (!okay) continue;
        Eigen::Matrix3Xd src(3, 3), dst(3, 3);
        for (int j = 0; j < 3; ++j) {
          src.col(j) = spts[s_id[j]];
          dst.col(j) = mpts[m_id[j]];
        }
        T = kabsch(src, dst);
        // model +z in the scene frame = R^T e_z (T maps scene -> model).
        if (P.use_up_prior && T.linear().row(2).dot(up) < cos_tilt) continue;
      }
      // The sampled points must land near their matches with agreeing normals.
      for (int j = 0; j < sample_size && okay; ++j)
        okay = (T * spts[s_id[j]] - mpts[m_id[j]]).squaredNorm() < tau2 &&
               (T.linear() * snrm[s_id[j]]).dot(mnrm[m_id[j]]) > cos_normal;
      if (!okay) continue;
      int inl = 0;
      for (int j = 0; j < nc; ++j)
        inl += (T * spts[corr[j].first] - mpts[corr[j].second]).squaredNorm() < tau2;
      if (inl < sample_size) continue;
      if (inl > best) {
        best = inl;
        const double w = std::min(0.999, static_cast<double>(best) / ns);
        const double denom = std::log(1.0 - std::pow(w, sample_size));
        if (denom < 0)
          needed = std::max<long>(P.ransac_min_iterations,
                                  static_cast<long>(std::ceil(std::log(1.0 - P.ransac_confidence) / denom)));
      }
      // Keep the `hypotheses` best distinct ones.
      const double ttol = 4.0 * voxel, rtol = 20.0 * 3.14159265358979323846 / 180.0;
      bool merged = false;
      for (auto& h : top) {
        if (similar(h.T, T, ttol, rtol)) {
          if (inl > h.inliers) {
            h.T = T;
            h.inliers = inl;
          }
          merged = true;
          break;
        }
      }
      if (!merged) {
        if (static_cast<int>(top.size()) < P.candidates) {
          top.push_back({T, inl, 0.0});
        } else {
          auto worst = std::min_element(top.begin(), top.end(),
                                        [](const Hypothesis& a, const Hypothesis& b) { return a.inliers < b.inliers; });
          if (inl > worst->inliers) *worst = {T, inl, 0.0};
        }
      }
    }
    res.ransac_iterations += it;
    for (const auto& h : top) hyps.push_back(h);
  }
  res.time_global = seconds_since(t0);
  if (hyps.empty()) {
    res.reason = "no transform hypothesis found (too few consistent feature matches)";
    return;
  }

  // ---- refine the best distinct hypotheses by ICP and choose by fitting error + up penalty.
  t0 = Clock::now();
  // Candidates (distinct, by consensus) are ranked by their fitting error on a scene subsample;
  // the best `hypotheses` get a coarse ICP.
  std::vector<Vec3> sub;
  const int stride = std::max(1, ns / P.coarse_points);
  for (int i = 0; i < ns; i += stride) sub.push_back(spts[i]);
  std::stable_sort(hyps.begin(), hyps.end(), [](const Hypothesis& a, const Hypothesis& b) { return a.inliers > b.inliers; });
  std::vector<Hypothesis> distinct;
  for (const auto& h : hyps) {
    bool dup = false;
    for (const auto& g : distinct) dup = dup || similar(g.T, h.T, 4.0 * voxel, 20.0 * 3.14159265358979323846 / 180.0);
    if (!dup) distinct.push_back(h);
  }
  for (auto& h : distinct) h.cost = measure(md, sub, h.T, tau).delta;
  std::stable_sort(distinct.begin(), distinct.end(), [](const Hypothesis& a, const Hypothesis& b) { return a.cost < b.cost; });
  if (static_cast<int>(distinct.size()) > P.hypotheses) distinct.resize(P.hypotheses);
  // Coarse: a short ICP on a subsample of the scene for every hypothesis; fine: the winner.
  auto cost_of = [&](const Fit& f, const Iso3& T) {
    const double up_cos = T.linear().row(2).dot(up);
    return f.delta / tau + (P.use_up_prior ? P.up_weight * (1.0 - up_cos) / 2.0 : 0.0);
  };
  double best_cost = std::numeric_limits<double>::infinity();
  Iso3 best_T = Iso3::Identity();
  for (auto& h : distinct) {
    const Iso3 T = icp(md, sub, h.T, P.icp_distance * voxel, P.coarse_icp_iterations, P.icp_tolerance);
    const double cost = cost_of(measure(md, sub, T, tau), T);
    if (cost < best_cost) {
      best_cost = cost;
      best_T = T;
    }
  }
  const Iso3 T = icp(md, spts, best_T, P.icp_distance * voxel, P.icp_iterations, P.icp_tolerance);
  const Fit f = measure(md, spts, T, tau);
  const double sigma = P.weight_sigma * voxel;
  res.transform = T.inverse().matrix();
  res.fitness = f.fitness;
  res.rmse = f.rmse;
  res.delta = f.delta;
  res.phi = std::exp(-f.delta * f.delta / (2 * sigma * sigma));
  res.up_cos = T.linear().row(2).dot(up);
  res.cost = cost_of(f, T);
  res.time_icp = seconds_since(t0);
  if (!res.transform.allFinite()) {
    res.reason = "registration produced a non-finite transform";
    res.transform.setIdentity();
    return;
  }
  res.success = true;
}

}  // namespace

// ---------------------------------------------------------------------------------------
double surface_area(const TriMesh& mesh) {
  double a = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Vec3 v0 = mesh.V.row(mesh.F(f, 0)).transpose();
    a += 0.5 * (Vec3(mesh.V.row(mesh.F(f, 1)).transpose()) - v0)
                   .cross(Vec3(mesh.V.row(mesh.F(f, 2)).transpose()) - v0)
                   .norm();
  }
  return a;
}

SurfaceSamples sample_surface(const TriMesh& mesh, int n, std::uint64_t seed) {
  validate_mesh(mesh);
  if (n <= 0) throw std::invalid_argument("number of samples must be positive");
  const Eigen::Index F = mesh.F.rows();
  std::vector<double> cum(F);
  std::vector<Vec3> normals(F);
  double total = 0;
  for (Eigen::Index f = 0; f < F; ++f) {
    const Vec3 v0 = mesh.V.row(mesh.F(f, 0)).transpose();
    const Vec3 c = (Vec3(mesh.V.row(mesh.F(f, 1)).transpose()) - v0).cross(Vec3(mesh.V.row(mesh.F(f, 2)).transpose()) - v0);
    const double a = 0.5 * c.norm();
    total += a;
    cum[f] = total;
    normals[f] = a > 0 ? c.normalized() : Vec3::Zero();
  }
  if (!(total > 0)) throw std::invalid_argument("mesh has no surface area");
  std::mt19937_64 rng(mix(seed));
  std::uniform_real_distribution<double> U(0.0, 1.0);
  SurfaceSamples s;
  s.points.resize(n, 3);
  s.normals.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    const double r = U(rng) * total;
    Eigen::Index f = std::lower_bound(cum.begin(), cum.end(), r) - cum.begin();
    f = std::min<Eigen::Index>(f, F - 1);
    while (f > 0 && normals[f].isZero()) --f;  // never a zero-area face
    double a = U(rng), b = U(rng);
    if (a + b > 1) {
      a = 1 - a;
      b = 1 - b;
    }
    const Vec3 v0 = mesh.V.row(mesh.F(f, 0)).transpose(), v1 = mesh.V.row(mesh.F(f, 1)).transpose(),
               v2 = mesh.V.row(mesh.F(f, 2)).transpose();
    s.points.row(i) = (v0 + a * (v1 - v0) + b * (v2 - v0)).transpose();
    s.normals.row(i) = normals[f].transpose();
  }
  return s;
}

ModelCloud model_from_mesh(const TriMesh& mesh, const RegistrationParams& params, std::uint64_t seed) {
  validate_mesh(mesh);
  const double area = surface_area(mesh);
  if (!(area > 0)) throw std::invalid_argument("mesh has no surface area");
  int n = params.model_samples;
  if (n <= 0) {
    const double h = params.voxel / 3.0;
    n = static_cast<int>(std::clamp(area / (h * h), 2000.0, 200000.0));
  }
  ModelCloud m;
  m.surface = sample_surface(mesh, n, seed);
  return m;
}

double rotation_error(const Mat3& Ra, const Mat3& Rb, const Vec3& axis) {
  if (axis.norm() > 0) {
    const Vec3 a = axis.normalized();
    const double c = std::clamp((Ra * a).dot(Rb * a), -1.0, 1.0);
    return std::acos(c);
  }
  const double c = std::clamp(((Ra.transpose() * Rb).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c);
}

// ---------------------------------------------------------------------------------------
struct Registrar::Model : ModelData {};

struct Registrar::Impl {
  RegistrationParams P;
  std::vector<std::unique_ptr<Model>> models;
  mutable std::shared_mutex mutex;  // add_models (unique) against the readers (shared)
};

Registrar::Registrar(const RegistrationParams& params) : impl_(std::make_unique<Impl>()) {
  validate(params);
  impl_->P = params;
}
Registrar::~Registrar() = default;
Registrar::Registrar(Registrar&&) noexcept = default;
Registrar& Registrar::operator=(Registrar&&) noexcept = default;

int Registrar::add_models(const std::vector<ModelCloud>& models) {
  const int n = static_cast<int>(models.size());
  std::vector<std::unique_ptr<Model>> prepared(n);
  for (auto& m : prepared) m = std::make_unique<Model>();
  const RegistrationParams& P = impl_->P;
  const int nthreads = P.threads > 0 ? P.threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(nthreads)
  for (int i = 0; i < n; ++i) prepare_model(models[i].surface, P, *prepared[i]);
  std::unique_lock<std::shared_mutex> lock(impl_->mutex);
  const int first = static_cast<int>(impl_->models.size());
  for (auto& m : prepared) impl_->models.push_back(std::move(m));
  return first;
}

int Registrar::size() const {
  std::shared_lock<std::shared_mutex> lock(impl_->mutex);
  return static_cast<int>(impl_->models.size());
}
const RegistrationParams& Registrar::params() const { return impl_->P; }
namespace {
void check_index(int i, std::size_t n) {
  if (i < 0 || static_cast<std::size_t>(i) >= n)
    throw std::invalid_argument("model index " + std::to_string(i) + " out of range [0, " + std::to_string(n) + ")");
}
}  // namespace
const Registrar::Model& Registrar::model(int i) const {
  std::shared_lock<std::shared_mutex> lock(impl_->mutex);
  check_index(i, impl_->models.size());
  return *impl_->models[i];  // models are never removed, so the reference stays valid
}
bool Registrar::model_ok(int i) const { return model(i).ok; }
const std::string& Registrar::model_reason(int i) const { return model(i).reason; }
int Registrar::model_points(int i) const { return model(i).nm; }
double Registrar::model_time(int i) const { return model(i).time; }

std::vector<RegistrationResult> Registrar::register_scene(const Points& scene, std::uint64_t seed,
                                                          const std::optional<Vec3>& viewpoint,
                                                          const std::vector<int>& which) const {
  const RegistrationParams& P = impl_->P;
  std::shared_lock<std::shared_mutex> lock(impl_->mutex);
  std::vector<int> idx = which;
  if (idx.empty()) {
    idx.resize(impl_->models.size());
    std::iota(idx.begin(), idx.end(), 0);
  }
  if (idx.empty()) throw std::invalid_argument("no models given");
  for (int i : idx) check_index(i, impl_->models.size());
  if (viewpoint && !viewpoint->allFinite()) throw std::invalid_argument("viewpoint must be finite");
  CloudN::Ptr raw = to_cloud(scene, nullptr);
  if (raw->empty()) throw std::invalid_argument("scene cloud has no finite points");

  const int nthreads = P.threads > 0 ? P.threads : omp_get_max_threads();
  std::vector<RegistrationResult> results(idx.size());
  const SceneData sd = prepare_scene(raw, P, viewpoint, nthreads);
  if (sd.ns < P.min_scene_points) {
    for (auto& r : results) {
      r.reason = "scene has " + std::to_string(sd.ns) + " points with normals after downsampling at voxel " +
                 std::to_string(P.voxel) + " m; at least " + std::to_string(P.min_scene_points) + " are needed";
      r.scene_points = sd.ns;
    }
    return results;
  }
#pragma omp parallel for schedule(dynamic, 1) num_threads(nthreads)
  for (int k = 0; k < static_cast<int>(idx.size()); ++k) {
    RegistrationResult& res = results[k];
    const ModelData& md = *impl_->models[idx[k]];
    res.scene_points = sd.ns;
    res.time_features = sd.time;
    res.model_points = md.nm;
    if (!md.ok) {
      res.reason = md.reason;
      continue;
    }
    register_one(md, sd, P, seed, res);
  }
  double total = 0;
  for (const auto& r : results)
    if (r.success) total += r.phi;
  for (auto& r : results) r.weight = (r.success && total > 0) ? r.phi / total : 0.0;
  return results;
}

std::vector<RegistrationResult> register_models(const Points& scene, const std::vector<ModelCloud>& models,
                                                const RegistrationParams& P) {
  Registrar reg(P);
  if (models.empty()) throw std::invalid_argument("no models given");
  if (!scene.array().isFinite().rowwise().all().any()) throw std::invalid_argument("scene cloud has no finite points");
  reg.add_models(models);
  std::vector<RegistrationResult> res =
      reg.register_scene(scene, P.seed, P.has_viewpoint ? std::optional<Vec3>(P.viewpoint) : std::nullopt);
  for (int i = 0; i < reg.size(); ++i) res[i].time_features += reg.model_time(i);
  return res;
}

}  // namespace bayesgrasp::vision

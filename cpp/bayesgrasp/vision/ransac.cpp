#include "bayesgrasp/vision/ransac.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include "bayesgrasp/common/random.hpp"

namespace bayesgrasp::vision {

namespace {
constexpr double kPi = 3.14159265358979323846;

// A minimal sample: scene and model point of each drawn correspondence.
struct Sample {
  int size = 0;
  int s[3] = {0, 0, 0}, m[3] = {0, 0, 0};
};

// One RANSAC problem: the clouds, the correspondences and the constants derived from the options.
class Problem {
 public:
  Problem(const OrientedPointsD& scene, const OrientedPointsD& model, const Correspondences& corr,
          const StepContext& context)
      : scene_(scene), model_(model), corr_(corr), c_(context), ransac_(context.options.ransac),
        prior_(context.options.up_prior) {
    tau2_ = c_.tau * c_.tau;
    min_edge_ = 2.0 * c_.voxel;
    cos_normal_ = std::cos(ransac_.max_normal_angle);
    cos_tilt_ = std::cos(prior_.max_tilt);
    four_dof_ = prior_.enabled && prior_.upright;
    // Rotation taking the scene's up onto +z (the model's up), for the 4-DOF hypotheses.
    R0_ = Eigen::Quaterniond::FromTwoVectors(c_.up, Vec3::UnitZ()).toRotationMatrix();
  }

  int sample_size() const { return four_dof_ ? 2 : 3; }
  int correspondences() const { return static_cast<int>(corr_.size()); }

  Sample draw(Rng& rng, std::uniform_int_distribution<int>& pick) const {
    Sample x;
    x.size = sample_size();
    for (int j = 0; j < x.size; ++j) {
      const int c = pick(rng);
      x.s[j] = corr_[c].first;
      x.m[j] = corr_[c].second;
    }
    return x;
  }

  /// The sample's transform, if it passes the pre-rejection tests.
  std::optional<Iso3> transform(const Sample& x) const {
    if (x.s[0] == x.s[1] || (x.size == 3 && (x.s[0] == x.s[2] || x.s[1] == x.s[2]))) return std::nullopt;
    const std::optional<Iso3> T = four_dof_ ? upright_transform(x) : free_transform(x);
    if (!T || !lands_on_matches(*T, x)) return std::nullopt;
    return T;
  }

  /// Correspondences within the inlier distance under T.
  int consensus(const Iso3& T) const {
    int inl = 0;
    for (const auto& c : corr_) inl += (T * scene_.points[c.first] - model_.points[c.second]).squaredNorm() < tau2_;
    return inl;
  }

 private:
  // Yaw about the up axis and a translation from two correspondences (the model's +z is the
  // scene's up): levelled scene points q = R0 p, then a rotation about z.
  std::optional<Iso3> upright_transform(const Sample& x) const {
    const auto& sp = scene_.points;
    const auto& mp = model_.points;
    const Vec3 qa = R0_ * sp[x.s[0]], qb = R0_ * sp[x.s[1]];
    const Vec3 dq = qb - qa, dm = mp[x.m[1]] - mp[x.m[0]];
    const double lq = dq.head<2>().norm(), lm = dm.head<2>().norm();
    const double sim = ransac_.edge_similarity;
    if (lq < min_edge_ || lm < min_edge_ || std::min(lq, lm) < sim * std::max(lq, lm) ||
        std::abs(dq.z() - dm.z()) > c_.tau)
      return std::nullopt;
    const double yaw = std::atan2(dm.y(), dm.x()) - std::atan2(dq.y(), dq.x());
    Iso3 T = Iso3::Identity();
    T.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix() * R0_;
    T.translation() = 0.5 * (mp[x.m[0]] + mp[x.m[1]]) - T.linear() * 0.5 * (sp[x.s[0]] + sp[x.s[1]]);
    return T;
  }

  // Kabsch from three correspondences whose triangle edges agree in length; with the up prior,
  // tilts beyond max_tilt are rejected.
  std::optional<Iso3> free_transform(const Sample& x) const {
    const auto& sp = scene_.points;
    const auto& mp = model_.points;
    const double sim = ransac_.edge_similarity;
    const int pairs[3][2] = {{0, 1}, {1, 2}, {0, 2}};
    for (const auto& pr : pairs) {
      const double ls = (sp[x.s[pr[0]]] - sp[x.s[pr[1]]]).norm();
      const double lm = (mp[x.m[pr[0]]] - mp[x.m[pr[1]]]).norm();
      if (ls < min_edge_ || lm < min_edge_ || std::min(ls, lm) < sim * std::max(ls, lm)) return std::nullopt;
    }
    Eigen::Matrix3Xd src(3, 3), dst(3, 3);
    for (int j = 0; j < 3; ++j) {
      src.col(j) = sp[x.s[j]];
      dst.col(j) = mp[x.m[j]];
    }
    const Iso3 T = kabsch(src, dst);
    // The model's +z in the scene frame is R^T e_z (T maps scene -> model).
    if (prior_.enabled && T.linear().row(2).dot(c_.up) < cos_tilt_) return std::nullopt;
    return T;
  }

  // The sampled points land near their matches, with agreeing normals.
  bool lands_on_matches(const Iso3& T, const Sample& x) const {
    for (int j = 0; j < x.size; ++j) {
      const int s = x.s[j], m = x.m[j];
      if (!((T * scene_.points[s] - model_.points[m]).squaredNorm() < tau2_ &&
            (T.linear() * scene_.normals[s]).dot(model_.normals[m]) > cos_normal_))
        return false;
    }
    return true;
  }

  const OrientedPointsD& scene_;
  const OrientedPointsD& model_;
  const Correspondences& corr_;
  const StepContext& c_;
  const RansacOptions& ransac_;
  const UpPrior& prior_;
  double tau2_ = 0, min_edge_ = 0, cos_normal_ = 0, cos_tilt_ = 0;
  bool four_dof_ = true;
  Mat3 R0_ = Mat3::Identity();
};

// Iterations needed for the confidence bound with the best consensus so far (inlier ratio
// best / scene points, capped at 0.999), at least min_iterations; `current` if undefined.
long needed_iterations(int best, int scene_points, int sample_size, const RansacOptions& o, long current) {
  const double w = std::min(0.999, static_cast<double>(best) / scene_points);
  const double denom = std::log(1.0 - std::pow(w, sample_size));
  if (!(denom < 0)) return current;
  return std::max<long>(o.min_iterations, static_cast<long>(std::ceil(std::log(1.0 - o.confidence) / denom)));
}

// Keeps the `capacity` best distinct hypotheses: T replaces a similar one if it has more inliers,
// else it joins, displacing the one with the fewest inliers once full.
void keep_distinct(std::vector<Hypothesis>& top, const Iso3& T, int inliers, int capacity, double voxel) {
  for (auto& h : top) {
    if (!same_hypothesis(h.T, T, voxel)) continue;
    if (inliers > h.inliers) {
      h.T = T;
      h.inliers = inliers;
    }
    return;
  }
  if (static_cast<int>(top.size()) < capacity) {
    top.push_back({T, inliers, 0.0});
    return;
  }
  auto worst = std::min_element(top.begin(), top.end(),
                                [](const Hypothesis& a, const Hypothesis& b) { return a.inliers < b.inliers; });
  if (inliers > worst->inliers) *worst = {T, inliers, 0.0};
}

// One restart: the distinct hypotheses it keeps; `iterations` counts its iterations.
std::vector<Hypothesis> restart(const Problem& problem, const StepContext& context, int scene_points, Rng& rng,
                                int& iterations) {
  const RansacOptions& o = context.options.ransac;
  std::uniform_int_distribution<int> pick(0, problem.correspondences() - 1);
  std::vector<Hypothesis> top;
  int best = 0;
  long needed = o.iterations;
  int it = 0;
  for (; it < o.iterations && it < needed; ++it) {
    const Sample x = problem.draw(rng, pick);
    const std::optional<Iso3> T = problem.transform(x);
    if (!T) continue;
    const int inl = problem.consensus(*T);
    if (inl < x.size) continue;
    if (inl > best) {
      best = inl;
      needed = needed_iterations(best, scene_points, x.size, o, needed);
    }
    keep_distinct(top, *T, inl, o.candidates, context.voxel);
  }
  iterations += it;
  return top;
}
}  // namespace

bool same_hypothesis(const Iso3& a, const Iso3& b, double voxel) {
  const double trans_tol = 4.0 * voxel, rot_tol = 20.0 * kPi / 180.0;
  const double ang = Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
  return ang < rot_tol && (a.translation() - b.translation()).norm() < trans_tol;
}

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

RansacResult ransac(const OrientedPointsD& scene, const OrientedPointsD& model, const Correspondences& corr,
                    const StepContext& context, std::uint64_t seed) {
  RansacResult out;
  if (corr.empty()) return out;
  const Problem problem(scene, model, corr, context);
  for (int r = 0; r < context.options.ransac.restarts; ++r) {
    Rng rng(mix_seed(seed * 0x100000001B3ull + static_cast<std::uint64_t>(r)));
    for (const Hypothesis& h : restart(problem, context, scene.size(), rng, out.iterations))
      out.hypotheses.push_back(h);
  }
  return out;
}

}  // namespace bayesgrasp::vision

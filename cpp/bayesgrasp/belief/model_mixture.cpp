#include "bayesgrasp/belief/model_mixture.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "bayesgrasp/belief/relative_pose.hpp"
#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp::belief {

namespace {

constexpr double kLog2Pi = 1.8378770664093453;

void check_channels(const RelativePoseGrid& grid, const MeasurementChannels& ch) {
  const long long k = ch.k, end_mean = ch.mean_c0 + k, end_var = ch.var_c0 + k;  // 64-bit: no overflow
  if (k < 1 || ch.mean_c0 < 0 || ch.var_c0 < 0 || end_mean > grid.channels() || end_var > grid.channels())
    throw std::invalid_argument("channels: mean and variance channels must lie inside the grid's " +
                                std::to_string(grid.channels()) + " channels");
}

/// Eq. 4.4's objective in scaled coordinates u = (p - prior) / prior_std: -log L - log prior.
struct PosePosterior {
  const RelativePoseGrid& grid;
  const MeasurementChannels& ch;
  const Eigen::Vector3d& grasp;
  const Eigen::VectorXd& m;
  const Eigen::Vector3d& prior;
  const ModelPoseOptions& o;

  RowMatrixXd poses(const optim::RowMatrixXd& U) const {
    RowMatrixXd P(U.rows(), 3);
    for (Eigen::Index r = 0; r < U.rows(); ++r)
      for (int c = 0; c < 3; ++c) P(r, c) = prior[c] + o.prior_std[c] * U(r, c);
    return P;
  }
  void operator()(const optim::RowMatrixXd& U, Eigen::VectorXd& f) const {
    const Eigen::VectorXd ll = measurement_log_likelihood(grid, ch, grasp, m, poses(U), o.measurement_noise);
    for (Eigen::Index r = 0; r < U.rows(); ++r) f[r] = -ll[r] + 0.5 * U.row(r).squaredNorm();
  }
};

}  // namespace

void ModelPoseOptions::validate() const {
  if (!prior_std.allFinite() || (prior_std.array() <= 0.0).any())
    throw std::invalid_argument("prior_std: must be three positive numbers (m, m, rad)");
  if (!(measurement_noise >= 0.0) || !std::isfinite(measurement_noise))
    throw std::invalid_argument("measurement_noise: must be >= 0 and finite");
  optim::validate(trust_region);
}

Eigen::VectorXd measurement_log_likelihood(const RelativePoseGrid& grid, const MeasurementChannels& ch,
                                           const Eigen::Vector3d& grasp, const Eigen::VectorXd& measurement,
                                           const RowMatrixXd& poses, double measurement_noise) {
  check_channels(grid, ch);
  if (measurement.size() != ch.k)
    throw std::invalid_argument("measurement: expected " + std::to_string(ch.k) + " joint angles, got " +
                                std::to_string(measurement.size()));
  if (!measurement.allFinite()) throw std::invalid_argument("measurement: contains NaN or infinity");
  RowMatrixXd a(1, 3);
  a << grasp[0], grasp[1], grasp[2];
  const RowMatrixXd mean = grid.interpolate_pairs(a, poses, ch.mean_c0, ch.k);
  const RowMatrixXd var = grid.interpolate_pairs(a, poses, ch.var_c0, ch.k);
  const double s2 = measurement_noise * measurement_noise;
  Eigen::VectorXd ll(poses.rows());
  for (Eigen::Index j = 0; j < poses.rows(); ++j) {
    double acc = 0.0;
    for (int c = 0; c < ch.k; ++c) {
      const double v = std::max(var(j, c), 1e-12) + s2, d = measurement[c] - mean(j, c);
      acc -= 0.5 * (d * d / v + std::log(v) + kLog2Pi);
    }
    ll[j] = acc;
  }
  return ll;
}

std::vector<ModelPoseUpdate> map_model_poses(const std::vector<const RelativePoseGrid*>& grids,
                                             const MeasurementChannels& channels, const Eigen::Vector3d& grasp,
                                             const Eigen::VectorXd& measurement, const RowMatrixXd& prior_poses,
                                             const ModelPoseOptions& options, int threads) {
  options.validate();
  if (!grasp.allFinite()) throw std::invalid_argument("grasp: must be finite (x, y, yaw)");
  if (prior_poses.rows() != static_cast<Eigen::Index>(grids.size()))
    throw std::invalid_argument("prior_poses: need one pose per model (" + std::to_string(grids.size()) + ")");
  check_planar_poses(prior_poses, "prior_poses");
  for (const RelativePoseGrid* g : grids) {
    if (!g) throw std::invalid_argument("grids: a model has no grid");
    check_channels(*g, channels);
  }
  if (measurement.size() != channels.k || !measurement.allFinite())
    throw std::invalid_argument("measurement: expected " + std::to_string(channels.k) + " finite joint angles");
  const int n = static_cast<int>(grids.size());
  std::vector<ModelPoseUpdate> out(static_cast<size_t>(n));
  const int nt = thread_count_for(threads, n);
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d prior = prior_poses.row(i).transpose();
    const PosePosterior post{*grids[i], channels, grasp, measurement, prior, options};
    const optim::Result r = optim::trust_region(post, Eigen::Vector3d::Zero(), optim::Bounds{}, options.trust_region);
    ModelPoseUpdate& u = out[static_cast<size_t>(i)];
    const RowMatrixXd p = post.poses(r.x.transpose());
    u.pose = Eigen::Vector3d(p(0, 0), p(0, 1), wrap_angle(p(0, 2)));
    u.log_prior = -0.5 * r.x.squaredNorm();
    u.log_likelihood = -r.f - u.log_prior;
    u.evaluations = r.evaluations;
    u.converged = r.converged;
  }
  return out;
}

ModelWeightUpdate update_model_weights(const Eigen::VectorXd& log_likelihoods, const Eigen::VectorXd& previous,
                                       bool recursive) {
  const Eigen::Index n = log_likelihoods.size();
  if (n == 0) throw std::invalid_argument("log_likelihoods: need at least one model");
  if (previous.size() != n) throw std::invalid_argument("previous: need one weight per model");
  if (!previous.allFinite() || (previous.array() < 0).any() || !(previous.sum() > 0))
    throw std::invalid_argument("previous: weights must be finite, >= 0 and not all zero");
  for (Eigen::Index i = 0; i < n; ++i)
    if (std::isnan(log_likelihoods[i]) || log_likelihoods[i] == std::numeric_limits<double>::infinity())
      throw std::invalid_argument("log_likelihoods: NaN or +infinity at index " + std::to_string(i));
  ModelWeightUpdate out;
  if (!(log_likelihoods.maxCoeff() > kLogMinLikelihood)) {  // every likelihood underflows: keep w(t-1)
    out.weights = previous / previous.sum();
    out.underflow = true;
    return out;
  }
  Eigen::VectorXd lw = log_likelihoods;
  if (recursive)
    for (Eigen::Index i = 0; i < n; ++i) lw[i] += previous[i] > 0 ? std::log(previous[i]) : -std::numeric_limits<double>::infinity();
  const double top = lw.maxCoeff();
  if (!std::isfinite(top)) {
    out.weights = previous / previous.sum();
    out.underflow = true;
    return out;
  }
  out.weights = (lw.array() - top).exp().matrix();
  out.weights /= out.weights.sum();
  return out;
}

bool resample_and_jitter(RowMatrixXd& poses, Eigen::VectorXd& log_weights, const Eigen::Vector3d& jitter_std,
                         double threshold, Rng& rng) {
  const Eigen::Index n = poses.rows();
  if (poses.cols() != 3) throw std::invalid_argument("poses: expected (N, 3) planar poses");
  if (log_weights.size() != n || n == 0) throw std::invalid_argument("log_weights: expected one per pose");
  if (!poses.allFinite()) throw std::invalid_argument("poses: contains NaN or infinity");
  if (!jitter_std.allFinite() || (jitter_std.array() < 0.0).any())
    throw std::invalid_argument("jitter_std: must be finite and >= 0");
  if (!(threshold >= 0.0 && threshold <= 1.0)) throw std::invalid_argument("threshold: must be in [0, 1]");
  const double total = log_sum_exp(log_weights);
  if (!std::isfinite(total)) return false;  // no weight (or +inf/NaN, left to the caller's checks)
  const Eigen::VectorXd w = normalised_weights(log_weights);
  if (1.0 / w.squaredNorm() >= threshold * static_cast<double>(n)) return false;
  const std::vector<int> idx = resample_indices(w, static_cast<int>(n), Resampling::Systematic, rng);
  std::normal_distribution<double> normal;
  RowMatrixXd out(n, 3);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) out(i, k) = poses(idx[static_cast<size_t>(i)], k) + jitter_std[k] * normal(rng);
  for (Eigen::Index i = 0; i < n; ++i) out(i, 2) = wrap_angle(out(i, 2));
  poses = std::move(out);
  log_weights.setConstant(total - std::log(static_cast<double>(n)));
  return true;
}

}  // namespace bayesgrasp::belief

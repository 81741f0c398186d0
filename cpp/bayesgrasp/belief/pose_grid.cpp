#include "bayesgrasp/belief/pose_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "bayesgrasp/belief/relative_pose.hpp"
#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp::belief {

RelativePoseGrid::RelativePoseGrid(std::array<double, 2> lo, std::array<double, 2> hi, int nx, int ny, int nyaw,
                                   RowMatrixXd values, Eigen::VectorXd outside)
    : lo_(lo), hi_(hi), nx_(nx), ny_(ny), nyaw_(nyaw), values_(std::move(values)), outside_(std::move(outside)) {
  if (nx < 2 || ny < 2 || nyaw < 2) throw std::invalid_argument("grid: need at least 2 nodes per axis");
  for (int d = 0; d < 2; ++d)
    if (!(std::isfinite(lo[d]) && std::isfinite(hi[d]) && hi[d] > lo[d]))
      throw std::invalid_argument("grid: bounds must be finite with hi > lo");
  if (values_.rows() != static_cast<Eigen::Index>(nx) * ny * nyaw)
    throw std::invalid_argument("grid: values has " + std::to_string(values_.rows()) + " rows, expected nx*ny*nyaw = " +
                                std::to_string(static_cast<long long>(nx) * ny * nyaw));
  if (values_.cols() < 1) throw std::invalid_argument("grid: values need at least one channel");
  if (!values_.allFinite()) throw std::invalid_argument("grid: values contain NaN or infinity");
  if (outside_.size() != values_.cols())
    throw std::invalid_argument("grid: outside needs one value (or NaN) per channel");
  channel_major_ = values_.cast<float>();
  sx_ = (nx - 1) / (hi[0] - lo[0]);
  sy_ = (ny - 1) / (hi[1] - lo[1]);
  syaw_ = nyaw / (2.0 * M_PI);
}

void RelativePoseGrid::at(double x, double y, double yaw, int c0, int nc, double* out) const {
  const bool in = x >= lo_[0] && x <= hi_[0] && y >= lo_[1] && y <= hi_[1];
  // Position along each axis in node units, clamped to the grid.
  const double u = std::clamp((x - lo_[0]) * sx_, 0.0, nx_ - 1.0);
  const double v = std::clamp((y - lo_[1]) * sy_, 0.0, ny_ - 1.0);
  double t = (yaw + M_PI) * syaw_;
  t -= nyaw_ * std::floor(t / nyaw_);  // [0, nyaw)
  const int i = std::min(static_cast<int>(u), nx_ - 2), j = std::min(static_cast<int>(v), ny_ - 2);
  int k = static_cast<int>(t);
  if (k >= nyaw_) k = nyaw_ - 1;
  const int k1 = (k + 1 == nyaw_) ? 0 : k + 1;
  const double fu = u - i, fv = v - j, ft = t - k;
  const double w[8] = {(1 - fu) * (1 - fv) * (1 - ft), (1 - fu) * (1 - fv) * ft, (1 - fu) * fv * (1 - ft),
                       (1 - fu) * fv * ft,             fu * (1 - fv) * (1 - ft), fu * (1 - fv) * ft,
                       fu * fv * (1 - ft),             fu * fv * ft};
  const Eigen::Index base00 = (static_cast<Eigen::Index>(i) * ny_ + j) * nyaw_;
  const Eigen::Index base01 = base00 + nyaw_, base10 = base00 + static_cast<Eigen::Index>(ny_) * nyaw_,
                     base11 = base10 + nyaw_;
  const Eigen::Index rows[8] = {base00 + k, base00 + k1, base01 + k, base01 + k1,
                                base10 + k, base10 + k1, base11 + k, base11 + k1};
  if (nc == 1) {
    if (!in && !std::isnan(outside_[c0])) {
      *out = outside_[c0];
      return;
    }
    const float* col = channel_major_.col(c0).data();
    double s = 0.0;
    for (int q = 0; q < 8; ++q) s += w[q] * col[rows[q]];
    *out = s;
    return;
  }
  for (int c = 0; c < nc; ++c) {
    const int ch = c0 + c;
    if (!in && !std::isnan(outside_[ch])) {
      out[c] = outside_[ch];
      continue;
    }
    double s = 0.0;
    for (int q = 0; q < 8; ++q) s += w[q] * values_(rows[q], ch);
    out[c] = s;
  }
}

RowMatrixXd RelativePoseGrid::interpolate(const RowMatrixXd& rel) const {
  check_planar_poses(rel, "rel");
  RowMatrixXd out(rel.rows(), channels());
  for (Eigen::Index p = 0; p < rel.rows(); ++p) at(rel(p, 0), rel(p, 1), rel(p, 2), 0, channels(), &out(p, 0));
  return out;
}

RowMatrixXd RelativePoseGrid::interpolate_pairs(const RowMatrixXd& A, const RowMatrixXd& P, int c0, int nc,
                                                int n_threads) const {
  check_planar_poses(A, "actions");
  check_planar_poses(P, "poses");
  // In 64 bits: c0 + nc overflows int for c0 near 2^31.
  if (c0 < 0 || nc < 1 || static_cast<long long>(c0) + nc > channels())
    throw std::invalid_argument("channels [" + std::to_string(c0) + ", " + std::to_string(static_cast<long long>(c0) + nc) +
                                "): out of range for a grid of " + std::to_string(channels()) + " channels");
  const Eigen::Index na = A.rows(), n = P.rows();
  RowMatrixXd out(na * n, nc);
  const std::vector<PlanarFrame> frames = planar_frames(P);
  const int threads = thread_count(n_threads, "n_threads");
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1 && na > 1)
  for (Eigen::Index a = 0; a < na; ++a)
    for (Eigen::Index j = 0; j < n; ++j) {
      double x, y;  // the action in object j's frame (the yaw difference is wrapped by at())
      frames[j].to_local(A(a, 0), A(a, 1), x, y);
      at(x, y, A(a, 2) - P(j, 2), c0, nc, &out(a * n + j, 0));
    }
  return out;
}

Eigen::VectorXd RelativePoseGrid::expected(const RowMatrixXd& A, const RowMatrixXd& P, const Eigen::VectorXd& w,
                                           int channel, int n_threads) const {
  check_planar_poses(A, "actions");
  check_planar_poses(P, "poses");
  if (channel < 0 || channel >= channels()) throw std::invalid_argument("channel: out of range");
  if (w.size() != P.rows()) throw std::invalid_argument("weights: expected one per pose");
  if (!w.allFinite() || (w.array() < 0).any()) throw std::invalid_argument("weights: must be finite and >= 0");
  const Eigen::Index na = A.rows(), n = P.rows();
  const std::vector<PlanarFrame> frames = planar_frames(P);
  Eigen::VectorXd out(na);
  const int threads = thread_count(n_threads, "n_threads");
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1 && na > 1)
  for (Eigen::Index a = 0; a < na; ++a) {
    double s = 0.0;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (w[j] == 0.0) continue;
      double x, y, v;
      frames[j].to_local(A(a, 0), A(a, 1), x, y);
      at(x, y, A(a, 2) - P(j, 2), channel, 1, &v);
      s += w[j] * v;
    }
    out[a] = s;
  }
  return out;
}

std::vector<EntropyEstimate> RelativePoseGrid::expected_posterior_entropy(
    const RowMatrixXd& A, const RowMatrixXd& P, const Eigen::VectorXd& log_weights, int mean_c0, int var_c0, int k,
    int n_samples, std::uint64_t seed, int n_threads) const {
  if (k < 1) throw std::invalid_argument("k: need at least one measurement output");
  if (log_weights.size() != P.rows()) throw std::invalid_argument("log_weights: expected one per pose");
  const RowMatrixXd mean = interpolate_pairs(A, P, mean_c0, k, n_threads);
  RowMatrixXd var = interpolate_pairs(A, P, var_c0, k, n_threads);
  var = var.cwiseMax(1e-12);  // interpolated variances stay positive
  return expected_posterior_entropy_batch(log_weights, mean, var, static_cast<int>(A.rows()), n_samples, seed,
                                          n_threads);
}

}  // namespace bayesgrasp::belief

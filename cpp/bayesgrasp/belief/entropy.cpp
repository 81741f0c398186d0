#include "bayesgrasp/belief/entropy.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp::belief {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

/// -sum p log p of p ∝ exp(l), without forming p (entries with l = -inf contribute 0).
double entropy_of_log(const double* l, int n) {
  double m = -kInf;
  for (int i = 0; i < n; ++i) m = std::max(m, l[i]);
  double s = 0.0, t = 0.0;
  for (int i = 0; i < n; ++i) {
    const double e = std::exp(l[i] - m);
    if (e > 0.0) { s += e; t += e * (l[i] - m); }
  }
  return std::log(s) - t / s;
}
}  // namespace

double weight_entropy(const Eigen::VectorXd& lw) {
  normalised_weights(lw);  // validates
  return entropy_of_log(lw.data(), static_cast<int>(lw.size()));
}

Bandwidth bandwidth_from_string(const std::string& s) {
  if (s == "scott") return Bandwidth::Scott;
  if (s == "silverman") return Bandwidth::Silverman;
  throw std::invalid_argument("bandwidth: expected 'scott' or 'silverman', got '" + s + "'");
}

namespace {

// The KDE's Gaussian kernel: covariance H = f^2 C (C the weighted covariance of the deviations
// from the weighted mean, f by Scott's or Silverman's rule), as its whitening W = chol(H)^-1 and
// the log normalising constant of N(0, H).
struct KdeKernel {
  Eigen::MatrixXd W;
  double log_norm = 0.0;
};

KdeKernel kde_kernel(const RowMatrixXd& Xc, const Eigen::VectorXd& w, const Eigen::VectorXd& mu,
                     const StateSpace& space, Bandwidth bw) {
  const int n = static_cast<int>(Xc.rows()), d = static_cast<int>(Xc.cols());
  const double sw2 = w.squaredNorm();
  const double neff = 1.0 / sw2;
  RowMatrixXd dev(n, d);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < d; ++k) dev(i, k) = space.difference(k, Xc(i, k), mu[k]);
  Eigen::MatrixXd C = dev.transpose() * w.asDiagonal() * dev;
  if (sw2 < 1.0) C /= (1.0 - sw2);
  const double factor = bw == Bandwidth::Scott ? std::pow(neff, -1.0 / (d + 4))
                                               : std::pow(neff * (d + 2) / 4.0, -1.0 / (d + 4));
  Eigen::MatrixXd H = factor * factor * C;
  Eigen::LLT<Eigen::MatrixXd> llt(H);
  const double ridge = std::max(1e-10 * H.diagonal().maxCoeff(), 1e-12);
  if (llt.info() != Eigen::Success || (llt.matrixL().toDenseMatrix().diagonal().array() <= 0.0).any()) {
    H.diagonal().array() += ridge;
    llt.compute(H);
  }
  const Eigen::MatrixXd L = llt.matrixL();
  if ((L.diagonal().array() <= 0.0).any() || !L.allFinite()) {
    H.diagonal().array() += ridge;
    llt.compute(H);
  }
  const Eigen::MatrixXd Lf = llt.matrixL();
  KdeKernel kernel;
  kernel.log_norm = -0.5 * d * std::log(2.0 * M_PI) - Lf.diagonal().array().log().sum();
  // Whitening W = L^-1 (lower triangular): Mahalanobis distance = |W diff|^2.
  kernel.W = Lf.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(d, d));
  return kernel;
}

// Squared Mahalanobis distance |W (x_i - x_j)|^2 with wrapped differences in wrapping dims
// (both in [low, high): |e| < period), W lower triangular.
double wrapped_mahalanobis(const RowMatrixXd& Xc, int i, int j, const Eigen::MatrixXd& W, const StateSpace& space,
                           const Eigen::VectorXd& period, std::vector<double>& diff) {
  const int d = static_cast<int>(Xc.cols());
  for (int k = 0; k < d; ++k) {
    double e = Xc(i, k) - Xc(j, k);
    if (space.wrap(k)) {
      if (e >= 0.5 * period[k]) e -= period[k];
      else if (e < -0.5 * period[k]) e += period[k];
    }
    diff[k] = e;
  }
  double q = 0.0;
  for (int r = 0; r < d; ++r) {
    double t = 0.0;
    for (int c = 0; c <= r; ++c) t += W(r, c) * diff[c];
    q += t * t;
  }
  return q;
}

// -sum_i w_i log p(x_i), p(x) = sum_j w_j N(x - x_j; 0, H), each inner sum by log-sum-exp.
double resubstitution_entropy(const RowMatrixXd& Xc, const Eigen::VectorXd& lw, const Eigen::VectorXd& w,
                              const KdeKernel& kernel, const StateSpace& space) {
  const int n = static_cast<int>(Xc.rows()), d = static_cast<int>(Xc.cols());
  const Eigen::VectorXd logw = lw.array() - log_sum_exp(lw);
  bool any_wrap = false;
  Eigen::VectorXd period(d);
  for (int k = 0; k < d; ++k) {
    any_wrap = any_wrap || space.wrap(k);
    period[k] = space.high[k] - space.low[k];
  }
  // Without wrapping dims, whiten the particles once; otherwise wrap each difference first.
  RowMatrixXd Z;
  if (!any_wrap) Z = Xc * kernel.W.transpose();
  double H_est = 0.0;
  std::vector<double> terms(n), diff(d);
  for (int i = 0; i < n; ++i) {
    if (w[i] == 0.0) continue;
    double mx = -kInf;
    for (int j = 0; j < n; ++j) {
      double q = 0.0;
      if (!any_wrap) {
        for (int k = 0; k < d; ++k) { const double e = Z(i, k) - Z(j, k); q += e * e; }
      } else {
        q = wrapped_mahalanobis(Xc, i, j, kernel.W, space, period, diff);
      }
      terms[j] = logw[j] - 0.5 * q;
      mx = std::max(mx, terms[j]);
    }
    double sum = 0.0;
    for (int j = 0; j < n; ++j) sum += std::exp(terms[j] - mx);
    H_est -= w[i] * (kernel.log_norm + mx + std::log(sum));
  }
  return H_est;
}

}  // namespace

double kde_entropy(const RowMatrixXd& X, const Eigen::VectorXd& lw, const StateSpace& space, Bandwidth bw) {
  space.validate();
  const int n = static_cast<int>(X.rows()), d = static_cast<int>(X.cols());
  if (n == 0) throw std::invalid_argument("particles: zero particles");
  if (d != space.dim()) throw std::invalid_argument("particles: column count differs from the bounds' dimension");
  if (!X.allFinite()) throw std::invalid_argument("particles: contains NaN or infinity");
  if (lw.size() != n) throw std::invalid_argument("log_weights: expected one per particle");
  const Eigen::VectorXd w = normalised_weights(lw);
  // Weighted mean (circular for wrapping dims) of the wrapped particles.
  const ParticleBelief tmp(space, X, lw);
  const RowMatrixXd& Xc = tmp.particles();
  const KdeKernel kernel = kde_kernel(Xc, w, tmp.mean(), space, bw);
  return resubstitution_entropy(Xc, lw, w, kernel, space);
}

namespace {

struct Draws {
  std::vector<double> u;  // n_samples stratified uniforms
  RowMatrixXd z;          // n_samples x K standard normals
};

Draws make_draws(int n_samples, int K, std::uint64_t seed) {
  Rng rng(seed);
  std::normal_distribution<double> normal;
  Draws d;
  d.u.resize(n_samples);
  d.z.resize(n_samples, K);
  for (int s = 0; s < n_samples; ++s) {
    d.u[s] = (s + uniform01(rng)) / n_samples;
    for (int k = 0; k < K; ++k) d.z(s, k) = normal(rng);
  }
  return d;
}

EntropyEstimate epe_one(const Eigen::VectorXd& lw, const std::vector<double>& cdf, const double* mean,
                        const double* var, int n, int K, const Draws& dr, std::vector<double>& buf) {
  // Per-particle constant: log w_i - 1/2 sum_k log var_ik.
  std::vector<double> base(n), inv(static_cast<size_t>(n) * K);
  for (int i = 0; i < n; ++i) {
    double c = lw[i];
    for (int k = 0; k < K; ++k) {
      const double v = var[i * K + k];
      c -= 0.5 * std::log(v);
      inv[i * K + k] = 1.0 / v;
    }
    base[i] = c;
  }
  const int S = static_cast<int>(dr.u.size());
  std::vector<double> m(K);
  buf.resize(n);
  double avg = 0.0, m2 = 0.0;  // Welford
  for (int s = 0; s < S; ++s) {
    int j = static_cast<int>(std::upper_bound(cdf.begin(), cdf.end(), dr.u[s]) - cdf.begin());
    if (j >= n) j = n - 1;
    for (int k = 0; k < K; ++k) m[k] = mean[j * K + k] + std::sqrt(var[j * K + k]) * dr.z(s, k);
    for (int i = 0; i < n; ++i) {
      double q = 0.0;
      for (int k = 0; k < K; ++k) {
        const double e = m[k] - mean[i * K + k];
        q += e * e * inv[i * K + k];
      }
      buf[i] = base[i] - 0.5 * q;
    }
    const double h = entropy_of_log(buf.data(), n);
    const double delta = h - avg;
    avg += delta / (s + 1);
    m2 += delta * (h - avg);
  }
  EntropyEstimate est;
  est.mean = avg;
  est.std_error = S > 1 ? std::sqrt(std::max(0.0, m2 / (S - 1)) / S) : 0.0;
  return est;
}

void check_epe_inputs(const Eigen::VectorXd& lw, const RowMatrixXd& mean, const RowMatrixXd& var, int n_actions,
                      int n_samples) {
  if (lw.size() == 0) throw std::invalid_argument("log_weights: zero particles");
  if (n_samples < 1) throw std::invalid_argument("n_samples: must be at least 1");
  if (n_actions < 1) throw std::invalid_argument("n_actions: must be at least 1");
  if (mean.rows() != lw.size() * n_actions || mean.cols() < 1)
    throw std::invalid_argument("mean: expected " + std::to_string(lw.size() * n_actions) +
                                " rows (actions x particles) and at least one column");
  if (var.rows() != mean.rows() || var.cols() != mean.cols())
    throw std::invalid_argument("var: expected the same shape as mean");
  if (!mean.allFinite()) throw std::invalid_argument("mean: contains NaN or infinity");
  if (!var.allFinite() || !(var.array() > 0.0).all())
    throw std::invalid_argument("var: must be finite and positive (include the measurement noise)");
}

}  // namespace

std::vector<EntropyEstimate> expected_posterior_entropy_batch(const Eigen::VectorXd& lw_in, const RowMatrixXd& mean,
                                                              const RowMatrixXd& var, int n_actions, int n_samples,
                                                              std::uint64_t seed, int n_threads) {
  check_epe_inputs(lw_in, mean, var, n_actions, n_samples);
  const Eigen::VectorXd w = normalised_weights(lw_in);
  const Eigen::VectorXd lw = lw_in.array() - log_sum_exp(lw_in);
  const int n = static_cast<int>(lw.size()), K = static_cast<int>(mean.cols());
  std::vector<double> cdf(n);
  double c = 0.0;
  for (int i = 0; i < n; ++i) cdf[i] = (c += w[i]);
  cdf[n - 1] = 1.0;
  const Draws dr = make_draws(n_samples, K, seed);
  std::vector<EntropyEstimate> out(n_actions);
  const int threads = thread_count(n_threads, "n_threads");
#pragma omp parallel num_threads(threads) if (threads > 1 && n_actions > 1)
  {
    std::vector<double> buf;
#pragma omp for schedule(static)
    for (int a = 0; a < n_actions; ++a)
      out[a] = epe_one(lw, cdf, mean.data() + static_cast<size_t>(a) * n * K,
                       var.data() + static_cast<size_t>(a) * n * K, n, K, dr, buf);
  }
  return out;
}

EntropyEstimate expected_posterior_entropy(const Eigen::VectorXd& lw, const RowMatrixXd& mean, const RowMatrixXd& var,
                                           int n_samples, std::uint64_t seed) {
  return expected_posterior_entropy_batch(lw, mean, var, 1, n_samples, seed, 1)[0];
}

}  // namespace bayesgrasp::belief

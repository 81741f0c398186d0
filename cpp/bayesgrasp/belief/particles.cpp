#include "bayesgrasp/belief/particles.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "bayesgrasp/common/interval.hpp"

namespace bayesgrasp::belief {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

void check_log_likelihood(const Eigen::VectorXd& ll, Eigen::Index n, const char* what) {
  if (ll.size() != n)
    throw std::invalid_argument(std::string(what) + ": expected " + std::to_string(n) + " values, got " +
                                std::to_string(ll.size()));
  for (Eigen::Index i = 0; i < n; ++i)
    if (std::isnan(ll[i]) || ll[i] == kInf)
      throw std::invalid_argument(std::string(what) + ": contains NaN or +infinity (at index " +
                                  std::to_string(i) + ")");
}
}  // namespace

// ---------------------------------------------------------------- StateSpace

StateSpace::StateSpace(Eigen::VectorXd lo, Eigen::VectorXd hi, std::vector<bool> w)
    : low(std::move(lo)), high(std::move(hi)), wraps(std::move(w)) {
  validate();
}

StateSpace StateSpace::planar_pose(double xl, double xh, double yl, double yh) {
  return StateSpace(Eigen::Vector3d(xl, yl, -M_PI), Eigen::Vector3d(xh, yh, M_PI), {false, false, true});
}

void StateSpace::validate() const {
  if (low.size() == 0) throw std::invalid_argument("bounds: dimension must be at least 1");
  if (low.size() != high.size()) throw std::invalid_argument("bounds: low and high have different lengths");
  if (!wraps.empty() && static_cast<Eigen::Index>(wraps.size()) != low.size())
    throw std::invalid_argument("wraps: expected one flag per dimension");
  if (!low.allFinite() || !high.allFinite()) throw std::invalid_argument("bounds: contains NaN or infinity");
  for (int k = 0; k < dim(); ++k) {
    if (low[k] > high[k])
      throw std::invalid_argument("bounds: low > high in dimension " + std::to_string(k) + " (" +
                                  std::to_string(low[k]) + " > " + std::to_string(high[k]) + ")");
    if (wrap(k) && !(high[k] > low[k]))
      throw std::invalid_argument("bounds: a wrapping dimension needs high > low (dimension " + std::to_string(k) + ")");
  }
}

double StateSpace::wrap_value(int k, double v) const {
  const double p = high[k] - low[k];
  double y = std::fmod(v - low[k], p);
  if (y < 0.0) y += p;
  if (y >= p) y = 0.0;  // rounding of fmod for tiny negative inputs
  return low[k] + y;
}

double StateSpace::difference(int k, double a, double b) const {
  double d = a - b;
  if (!wrap(k)) return d;
  const double p = high[k] - low[k];
  d = std::fmod(d + 0.5 * p, p);
  if (d < 0.0) d += p;
  return d - 0.5 * p;
}

bool StateSpace::contains(const double* x) const {
  for (int k = 0; k < dim(); ++k)
    if (!wrap(k) && (x[k] < low[k] || x[k] > high[k])) return false;
  return true;
}

void StateSpace::canonicalise(RowMatrixXd& X, const char* what) const {
  if (X.cols() != dim())
    throw std::invalid_argument(std::string(what) + ": expected " + std::to_string(dim()) + " columns, got " +
                                std::to_string(X.cols()));
  if (!X.allFinite()) throw std::invalid_argument(std::string(what) + ": contains NaN or infinity");
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    for (int k = 0; k < dim(); ++k)
      if (wrap(k)) X(i, k) = wrap_value(k, X(i, k));
    if (!contains(&X(i, 0)))
      throw std::invalid_argument(std::string(what) + ": row " + std::to_string(i) + " lies outside the bounds");
  }
}

// ---------------------------------------------------------------- weights, resampling

Resampling resampling_from_string(const std::string& s) {
  if (s == "systematic") return Resampling::Systematic;
  if (s == "stratified") return Resampling::Stratified;
  if (s == "multinomial") return Resampling::Multinomial;
  throw std::invalid_argument("scheme: expected 'systematic', 'stratified' or 'multinomial', got '" + s + "'");
}

double log_sum_exp(const Eigen::VectorXd& v) {
  if (v.size() == 0) return -kInf;
  const double m = v.maxCoeff();
  if (m == -kInf) return -kInf;
  return m + std::log((v.array() - m).exp().sum());
}

Eigen::VectorXd normalised_weights(const Eigen::VectorXd& lw) {
  if (lw.size() == 0) throw std::invalid_argument("log_weights: zero particles");
  check_log_likelihood(lw, lw.size(), "log_weights");
  const double m = lw.maxCoeff();
  if (m == -kInf) throw std::invalid_argument("log_weights: all weights are zero");
  Eigen::VectorXd w = (lw.array() - m).exp();
  return w / w.sum();
}

std::vector<int> resample_indices(const Eigen::VectorXd& w, int n, Resampling scheme, Rng& rng) {
  const int N = static_cast<int>(w.size());
  if (N == 0) throw std::invalid_argument("weights: zero particles");
  if (n < 1) throw std::invalid_argument("n: must be at least 1");
  std::vector<int> idx(n);
  // Cumulative sum, last entry forced to exactly 1.
  std::vector<double> c(N);
  double s = 0.0;
  for (int i = 0; i < N; ++i) {
    if (!(w[i] >= 0.0) || !std::isfinite(w[i])) throw std::invalid_argument("weights: must be finite and >= 0");
    s += w[i];
    c[i] = s;
  }
  if (!(s > 0.0)) throw std::invalid_argument("weights: all weights are zero");
  for (double& ci : c) ci /= s;
  c[N - 1] = 1.0;
  if (scheme == Resampling::Multinomial) {
    for (int m = 0; m < n; ++m) {
      const double u = uniform01(rng);
      idx[m] = static_cast<int>(std::upper_bound(c.begin(), c.end(), u) - c.begin());
      if (idx[m] >= N) idx[m] = N - 1;
    }
    return idx;
  }
  const double u0 = uniform01(rng);
  int i = 0;
  for (int m = 0; m < n; ++m) {
    const double u = (m + (scheme == Resampling::Systematic ? u0 : (m == 0 ? u0 : uniform01(rng)))) / n;
    while (i < N - 1 && c[i] <= u) ++i;
    idx[m] = i;
  }
  return idx;
}

// ---------------------------------------------------------------- ParticleBelief

ParticleBelief::ParticleBelief(StateSpace space, RowMatrixXd particles, Eigen::VectorXd log_weights)
    : space_(std::move(space)), X_(std::move(particles)), lw_(std::move(log_weights)) {
  space_.validate();
  if (X_.rows() == 0) throw std::invalid_argument("particles: zero particles");
  space_.canonicalise(X_, "particles");
  if (lw_.size() == 0) {
    lw_ = Eigen::VectorXd::Constant(X_.rows(), -std::log(static_cast<double>(X_.rows())));
  } else {
    if (lw_.size() != X_.rows()) throw std::invalid_argument("log_weights: expected one per particle");
    normalised_weights(lw_);  // validates (NaN, all zero)
    normalise();
  }
}

constexpr int kMaxParticles = 10000000;  // 10^7 particles: hundreds of MB of poses and weights

ParticleBelief ParticleBelief::uniform(const StateSpace& space, int n, Rng& rng) {
  space.validate();
  if (n < 1) throw std::invalid_argument("n: zero particles");
  if (n > kMaxParticles) throw std::invalid_argument("n: at most " + std::to_string(kMaxParticles) + " particles");
  RowMatrixXd X(n, space.dim());
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < space.dim(); ++k) {
      X(i, k) = space.low[k] + (space.high[k] - space.low[k]) * uniform01(rng);
      if (space.wrap(k)) X(i, k) = space.wrap_value(k, X(i, k));
    }
  return ParticleBelief(space, std::move(X));
}

ParticleBelief ParticleBelief::gaussian(const StateSpace& space, const Eigen::VectorXd& mean,
                                        const Eigen::VectorXd& std, int n, Rng& rng) {
  space.validate();
  if (n < 1) throw std::invalid_argument("n: zero particles");
  if (n > kMaxParticles) throw std::invalid_argument("n: at most " + std::to_string(kMaxParticles) + " particles");
  if (mean.size() != space.dim() || !mean.allFinite())
    throw std::invalid_argument("mean: expected a finite vector of the state's dimension");
  if (std.size() != space.dim() || !std.allFinite() || (std.array() < 0.0).any())
    throw std::invalid_argument("std: expected a finite, non-negative vector of the state's dimension");
  std::normal_distribution<double> normal;
  RowMatrixXd X(n, space.dim());
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < space.dim(); ++k) {
      double v = mean[k] + std[k] * normal(rng);
      if (space.wrap(k)) {
        v = space.wrap_value(k, v);
      } else {
        for (int t = 0; t < 1000 && (v < space.low[k] || v > space.high[k]); ++t) v = mean[k] + std[k] * normal(rng);
        v = std::min(std::max(v, space.low[k]), space.high[k]);
      }
      X(i, k) = v;
    }
  return ParticleBelief(space, std::move(X));
}

void ParticleBelief::normalise() { lw_.array() -= log_sum_exp(lw_); }

double ParticleBelief::ess() const { return 1.0 / weights().squaredNorm(); }

Eigen::VectorXd ParticleBelief::mean() const {
  const Eigen::VectorXd w = weights();
  Eigen::VectorXd m(dim());
  for (int k = 0; k < dim(); ++k) {
    if (space_.wrap(k)) {
      const double p = space_.high[k] - space_.low[k], s = 2.0 * M_PI / p;
      double c = 0.0, sn = 0.0;
      for (int i = 0; i < size(); ++i) {
        c += w[i] * std::cos(s * (X_(i, k) - space_.low[k]));
        sn += w[i] * std::sin(s * (X_(i, k) - space_.low[k]));
      }
      m[k] = space_.wrap_value(k, space_.low[k] + std::atan2(sn, c) / s);
    } else {
      m[k] = w.dot(X_.col(k));
    }
  }
  return m;
}

bool ParticleBelief::reweight(const Eigen::VectorXd& ll) {
  check_log_likelihood(ll, size(), "log_likelihood");
  Eigen::VectorXd lw = lw_ + ll;
  if (lw.maxCoeff() == -kInf) {
    lw_.setConstant(-std::log(static_cast<double>(size())));
    return true;
  }
  lw_ = lw;
  normalise();
  return false;
}

bool ParticleBelief::update(const BatchLogLikelihood& f) {
  Eigen::VectorXd ll(size());
  f(X_, ll);
  return reweight(ll);
}

void ParticleBelief::resample(Rng& rng, Resampling scheme, int n) {
  if (n < 0) throw std::invalid_argument("n: must be >= 0 (0 = keep the particle count), got " + std::to_string(n));
  if (n > kMaxParticles) throw std::invalid_argument("n: at most " + std::to_string(kMaxParticles) + " particles");
  if (n == 0) n = size();
  const std::vector<int> idx = resample_indices(weights(), n, scheme, rng);
  RowMatrixXd Y(n, dim());
  for (int m = 0; m < n; ++m) Y.row(m) = X_.row(idx[m]);
  X_.swap(Y);
  lw_ = Eigen::VectorXd::Constant(n, -std::log(static_cast<double>(n)));
}

bool ParticleBelief::resample_if_needed(Rng& rng, double threshold, Resampling scheme) {
  if (ess() < threshold * size()) {
    resample(rng, scheme);
    return true;
  }
  return false;
}

MetropolisStats ParticleBelief::metropolis(const BatchLogLikelihood& f, const Eigen::VectorXd& step,
                                           int n_steps, Rng& rng) {
  if (n_steps < 0) throw std::invalid_argument("n_steps: must be >= 0");
  if (step.size() != dim() || !step.allFinite() || (step.array() < 0.0).any())
    throw std::invalid_argument("step: expected a finite, non-negative vector of the state's dimension");
  MetropolisStats st;
  if (n_steps == 0) return st;
  const int n = size(), d = dim();
  Eigen::VectorXd cur(n), prop(n);
  f(X_, cur);
  check_log_likelihood(cur, n, "log_target");
  st.evaluations += n;
  std::normal_distribution<double> normal;
  RowMatrixXd Y(n, d);
  std::vector<char> inside(n);
  long long accepted = 0;
  for (int s = 0; s < n_steps; ++s) {
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < d; ++k) {
        double v = X_(i, k) + step[k] * normal(rng);
        if (space_.wrap(k)) v = space_.wrap_value(k, v);
        Y(i, k) = v;
      }
      inside[i] = space_.contains(&Y(i, 0));
      if (!inside[i]) Y.row(i) = X_.row(i);  // keep the callback's input inside the box
    }
    f(Y, prop);
    check_log_likelihood(prop, n, "log_target");
    st.evaluations += n;
    for (int i = 0; i < n; ++i) {
      const double u = uniform01(rng);  // drawn for every particle: the stream does not depend on f
      if (!inside[i] || prop[i] == -kInf) continue;
      if (prop[i] >= cur[i] || std::log(u) < prop[i] - cur[i]) {
        X_.row(i) = Y.row(i);
        cur[i] = prop[i];
        ++accepted;
      }
    }
  }
  st.acceptance_rate = static_cast<double>(accepted) / (static_cast<double>(n) * n_steps);
  return st;
}

void ParticleBelief::roughen(Rng& rng, double kk) {
  if (!(kk >= 0.0) || !std::isfinite(kk)) throw std::invalid_argument("k: must be finite and >= 0");
  const int n = size(), d = dim();
  const double scale = kk * std::pow(static_cast<double>(n), -1.0 / d);
  std::normal_distribution<double> normal;
  Eigen::VectorXd sigma(d);
  std::vector<double> v(n);
  for (int k = 0; k < d; ++k) {
    double spread;
    if (space_.wrap(k)) {  // shortest covering arc = period - largest gap between sorted angles
      const double p = space_.high[k] - space_.low[k];
      for (int i = 0; i < n; ++i) v[i] = X_(i, k);
      std::sort(v.begin(), v.end());
      double gap = v[0] + p - v[n - 1];
      for (int i = 1; i < n; ++i) gap = std::max(gap, v[i] - v[i - 1]);
      spread = p - gap;
    } else {
      spread = X_.col(k).maxCoeff() - X_.col(k).minCoeff();
    }
    sigma[k] = scale * spread;
  }
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < d; ++k) {
      const double y = X_(i, k) + sigma[k] * normal(rng);
      X_(i, k) = space_.wrap(k) ? space_.wrap_value(k, y) : reflect_into(y, space_.low[k], space_.high[k]);
    }
}

}  // namespace bayesgrasp::belief

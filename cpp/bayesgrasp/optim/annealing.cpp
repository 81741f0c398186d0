#include "bayesgrasp/optim/annealing.hpp"

#include <cmath>

#include "bayesgrasp/common/interval.hpp"
#include "bayesgrasp/common/random.hpp"

namespace bayesgrasp::optim {

Result simulated_annealing(const BatchObjective& fun, const Bounds& b, const AnnealingOptions& o) {
  validate_bounds(b);
  if (o.n_chains < 1) throw std::invalid_argument("n_chains: must be at least 1");
  if (std::isnan(o.t0) || std::isinf(o.t0)) throw std::invalid_argument("t0: must be finite (<= 0: from the initial points)");
  if (o.max_iter < 0) throw std::invalid_argument("max_iter: must be >= 0");
  if (!(o.cooling > 0.0 && o.cooling <= 1.0)) throw std::invalid_argument("cooling: must be in (0, 1]");
  if (!(o.step > 0.0)) throw std::invalid_argument("step: must be positive");
  if (!(o.step_min > 0.0) || !(o.step_max >= o.step_min))
    throw std::invalid_argument("step_min, step_max: need 0 < step_min <= step_max");
  if (o.adapt_interval < 0) throw std::invalid_argument("adapt_interval: must be >= 0");
  if (!(o.adapt_factor > 1.0)) throw std::invalid_argument("adapt_factor: must be > 1");
  if (!(o.target_acceptance > 0.0 && o.target_acceptance < 1.0))
    throw std::invalid_argument("target_acceptance: must be in (0, 1)");
  const int n = o.n_chains, d = b.dim();
  validate_population(o, n, d, "n_chains");

  Rng rng(o.seed);
  std::normal_distribution<double> normal;
  const Eigen::VectorXd range = b.range();
  RowMatrixXd X(n, d);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < d; ++k)
      X(i, k) = o.init.size() ? std::min(std::max(o.init(i, k), b.low[k]), b.high[k])
                              : b.low[k] + range[k] * uniform01(rng);
  Evaluator eval(fun);
  Eigen::VectorXd f(n), fy(n);
  eval(X, f);
  double t0 = o.t0;
  if (!(t0 > 0.0)) {
    double m = 0.0, s = 0.0;
    int c = 0;
    for (int i = 0; i < n; ++i)
      if (std::isfinite(f[i])) { m += f[i]; s += f[i] * f[i]; ++c; }
    t0 = c > 1 ? std::sqrt(std::max(0.0, (s - m * m / c) / (c - 1))) : 0.0;
    if (!(t0 > 0.0)) t0 = 1.0;
  }
  Eigen::Index bi;
  double bf = f.minCoeff(&bi);
  Eigen::VectorXd bx = X.row(bi).transpose();
  Result r;
  if (o.record_history) r.history.push_back(bf);
  RowMatrixXd Y(n, d);
  Eigen::VectorXd step = Eigen::VectorXd::Constant(n, std::min(std::max(o.step, o.step_min), o.step_max));
  Eigen::VectorXi accepted = Eigen::VectorXi::Zero(n);
  double T = t0;
  int it = 0;
  for (; it < o.max_iter && !(bf <= o.target); ++it) {
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < d; ++k)
        Y(i, k) = reflect_into(X(i, k) + step[i] * range[k] * normal(rng), b.low[k], b.high[k]);
    eval(Y, fy);
    for (int i = 0; i < n; ++i) {
      const double u = uniform01(rng);  // drawn for every chain: the stream does not depend on f
      const double df = fy[i] - f[i];
      if (df <= 0.0 || (std::isfinite(df) && u < std::exp(-df / T))) {
        X.row(i) = Y.row(i);
        f[i] = fy[i];
        ++accepted[i];
        if (f[i] < bf) { bf = f[i]; bx = X.row(i).transpose(); }
      }
    }
    T *= o.cooling;
    if (o.adapt_interval > 0 && (it + 1) % o.adapt_interval == 0) {
      for (int i = 0; i < n; ++i) {
        const double rate = static_cast<double>(accepted[i]) / o.adapt_interval;
        step[i] = rate > o.target_acceptance ? step[i] * o.adapt_factor : step[i] / o.adapt_factor;
        step[i] = std::min(std::max(step[i], o.step_min), o.step_max);
      }
      accepted.setZero();
    }
    if (o.record_history) r.history.push_back(bf);
  }
  finish(r, bx, bf, it, eval.evaluations(), o.target);
  return r;
}

}  // namespace bayesgrasp::optim

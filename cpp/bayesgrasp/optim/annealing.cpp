#include "bayesgrasp/optim/annealing.hpp"

#include <cmath>

#include "bayesgrasp/common/interval.hpp"
#include "bayesgrasp/common/random.hpp"

namespace bayesgrasp::optim {

void validate(const AnnealingOptions& o) {
  require_at_least(o.n_chains, 1, "n_chains");
  require_at_least(o.max_iter, 0, "max_iter");
  require_finite(o.t0, "t0");  // <= 0: from the initial points
  if (!(o.cooling > 0.0 && o.cooling <= 1.0)) bad_field("cooling", "in (0, 1]", number_str(o.cooling));
  require_positive(o.step, "step");
  require_positive(o.step_min, "step_min");
  if (!(o.step_max >= o.step_min) || !std::isfinite(o.step_max))
    bad_field("step_max", "finite and >= step_min", number_str(o.step_max));
  require_at_least(o.adapt_interval, 0, "adapt_interval");
  if (!(o.adapt_factor > 1.0) || !std::isfinite(o.adapt_factor))
    bad_field("adapt_factor", "finite and > 1", number_str(o.adapt_factor));
  require_open(o.target_acceptance, 0, 1, "target_acceptance");
  validate_shared(o);
}

Result simulated_annealing(const BatchObjective& fun, const Bounds& b, const AnnealingOptions& o) {
  validate_bounds(b);
  validate(o);
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

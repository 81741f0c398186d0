#include "bayesgrasp/optim/descent.hpp"

#include <cmath>

namespace bayesgrasp::optim {

Eigen::VectorXd project(const Eigen::VectorXd& x, const Bounds& b) {
  if (b.low.size() == 0) return x;
  return x.cwiseMax(b.low).cwiseMin(b.high);
}

void validate_start(const Eigen::VectorXd& x0, const Bounds& b, double h) {
  if (x0.size() == 0) throw std::invalid_argument("x0: must have at least one entry");
  if (!x0.allFinite()) throw std::invalid_argument("x0: contains NaN or infinity");
  if (b.low.size() || b.high.size()) {
    validate_bounds(b);
    if (b.dim() != x0.size()) throw std::invalid_argument("bounds: dimension differs from x0");
  }
  if (!(h > 0.0)) throw std::invalid_argument("h: must be positive");
}

double start_value(Evaluator& eval, const Eigen::VectorXd& x) {
  const double f = eval.at(x);
  if (!std::isfinite(f)) throw std::invalid_argument("x0: objective is not finite at the start point");
  return f;
}

CentralDifferences::CentralDifferences(const Eigen::VectorXd& x, double h)
    : points(2 * x.size(), x.size()), steps(x.size()) {
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    steps[k] = h * std::max(1.0, std::abs(x[k]));
    points.row(2 * k) = x.transpose();
    points.row(2 * k + 1) = x.transpose();
    points(2 * k, k) += steps[k];
    points(2 * k + 1, k) -= steps[k];
  }
}

Eigen::VectorXd numerical_gradient(Evaluator& eval, const Eigen::VectorXd& x, double h) {
  const CentralDifferences cd(x, h);
  Eigen::VectorXd f;
  eval(cd.points, f);
  Eigen::VectorXd g(x.size());
  for (Eigen::Index k = 0; k < x.size(); ++k) g[k] = (f[2 * k] - f[2 * k + 1]) / (2.0 * cd.steps[k]);
  return g;
}

void validate(const DescentOptions& o) {
  require_at_least(o.max_iter, 0, "max_iter");
  require_positive(o.h, "h");
  require_positive(o.t0, "t0");
  require_open(o.armijo, 0, 1, "armijo");
  require_open(o.backtrack, 0, 1, "backtrack");
  require_at_least(o.max_backtrack, 0, "max_backtrack");
  require_non_negative(o.gtol, "gtol");
  require_non_negative(o.ftol, "ftol");
}

Result steepest_descent(const BatchObjective& fun, const Eigen::VectorXd& x0_, const Bounds& b,
                        const DescentOptions& o) {
  validate(o);
  validate_start(x0_, b, o.h);
  Evaluator eval(fun);
  Eigen::VectorXd x = project(x0_, b);
  double f = start_value(eval, x);
  Result r;
  if (o.record_history) r.history.push_back(f);
  double t = o.t0;
  int it = 0;
  r.message = "iteration budget used";
  for (; it < o.max_iter; ++it) {
    const Eigen::VectorXd g = numerical_gradient(eval, x, o.h);
    // Projected-gradient stationarity measure.
    const double pg = (project(x - g, b) - x).lpNorm<Eigen::Infinity>();
    if (!(pg > o.gtol)) { r.converged = true; r.message = "gradient below gtol"; break; }
    bool accepted = false;
    Eigen::VectorXd xn;
    double fn = f;
    for (int k = 0; k < o.max_backtrack; ++k, t *= o.backtrack) {
      xn = project(x - t * g, b);
      fn = eval.at(xn);
      if (fn <= f - o.armijo * g.dot(x - xn)) { accepted = true; break; }
    }
    if (!accepted) { r.converged = true; r.message = "line search found no decrease"; break; }
    const double df = f - fn;
    x = xn;
    f = fn;
    if (o.record_history) r.history.push_back(f);
    t *= 2.0;
    if (df <= o.ftol * std::max(1.0, std::abs(f))) { ++it; r.converged = true; r.message = "relative decrease below ftol"; break; }
  }
  set_outcome(r, x, f, it, eval.evaluations());
  return r;
}

}  // namespace bayesgrasp::optim

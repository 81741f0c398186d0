#include "bayesgrasp/optim/pso.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "bayesgrasp/common/random.hpp"

namespace bayesgrasp::optim {

void validate(const PSOOptions& o) {
  require_at_least(o.n_particles, 1, "n_particles");
  require_at_least(o.max_iter, 0, "max_iter");
  require_positive(o.vmax_fraction, "vmax_fraction");
  require_finite(o.inertia, "inertia");
  require_finite(o.c1, "c1");
  require_finite(o.c2, "c2");
  require_at_least(o.stall_iter, 0, "stall_iter");
  require_non_negative(o.ftol, "ftol");
  validate_shared(o);
}

Result pso(const BatchObjective& fun, const Bounds& b, const PSOOptions& o) {
  validate_bounds(b);
  validate(o);
  const int n = o.n_particles, d = b.dim();
  validate_population(o, n, d, "n_particles");

  Rng rng(o.seed);
  const Eigen::VectorXd range = b.range();
  const Eigen::VectorXd vmax = o.vmax_fraction * range;
  RowMatrixXd X(n, d), V(n, d);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < d; ++k) {
      X(i, k) = o.init.size() ? std::min(std::max(o.init(i, k), b.low[k]), b.high[k])
                              : b.low[k] + range[k] * uniform01(rng);
      V(i, k) = vmax[k] * (2.0 * uniform01(rng) - 1.0);
    }
  Evaluator eval(fun);
  Eigen::VectorXd f(n);
  eval(X, f);
  RowMatrixXd P = X;            // personal bests
  Eigen::VectorXd pf = f;
  Eigen::Index g;
  double gf = pf.minCoeff(&g);
  Eigen::VectorXd gx = P.row(g).transpose();

  Result r;
  if (o.record_history) r.history.push_back(gf);
  int stall = 0;
  int it = 0;
  for (; it < o.max_iter && !(gf <= o.target); ++it) {
    for (int i = 0; i < n; ++i) {
      double* x = &X(i, 0);
      double* v = &V(i, 0);
      const double* p = &P(i, 0);
      for (int k = 0; k < d; ++k) {
        const double r1 = uniform01(rng), r2 = uniform01(rng);
        double vk = o.inertia * v[k] + o.c1 * r1 * (p[k] - x[k]) + o.c2 * r2 * (gx[k] - x[k]);
        vk = std::min(std::max(vk, -vmax[k]), vmax[k]);
        double xk = x[k] + vk;
        if (xk < b.low[k]) { xk = b.low[k]; vk = 0.0; }
        else if (xk > b.high[k]) { xk = b.high[k]; vk = 0.0; }
        x[k] = xk;
        v[k] = vk;
      }
    }
    eval(X, f);
    const double before = gf;
    for (int i = 0; i < n; ++i)
      if (f[i] < pf[i]) {
        pf[i] = f[i];
        P.row(i) = X.row(i);
        if (f[i] < gf) { gf = f[i]; gx = X.row(i).transpose(); }
      }
    if (o.record_history) r.history.push_back(gf);
    if (o.stall_iter > 0) {
      stall = (before - gf > o.ftol) ? 0 : stall + 1;
      if (stall >= o.stall_iter) { ++it; r.converged = true; r.message = "no improvement for stall_iter iterations"; break; }
    }
  }
  set_outcome(r, gx, gf, it, eval.evaluations());
  if (gf <= o.target) { r.converged = true; r.message = "target reached"; }
  if (r.message.empty()) r.message = "iteration budget used";
  return r;
}

}  // namespace bayesgrasp::optim

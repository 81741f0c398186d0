#include "bayesgrasp/optim/firefly.hpp"

#include <cmath>

#include "bayesgrasp/common/random.hpp"

namespace bayesgrasp::optim {

void validate(const FireflyOptions& o) {
  require_at_least(o.n_fireflies, 1, "n_fireflies");
  require_at_least(o.max_iter, 0, "max_iter");
  require_non_negative(o.beta0, "beta0");
  require_non_negative(o.gamma, "gamma");
  require_non_negative(o.alpha, "alpha");
  if (!(o.alpha_decay > 0.0 && o.alpha_decay <= 1.0)) bad_field("alpha_decay", "in (0, 1]", number_str(o.alpha_decay));
  validate_shared(o);
}

Result firefly(const BatchObjective& fun, const Bounds& b, const FireflyOptions& o) {
  validate_bounds(b);
  validate(o);
  const int n = o.n_fireflies, d = b.dim();
  validate_population(o, n, d, "n_fireflies");

  Rng rng(o.seed);
  const Eigen::VectorXd range = b.range();
  // Work in unit-box coordinates U in [0, 1]^D; X = low + U * range.
  RowMatrixXd U(n, d), X(n, d);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < d; ++k)
      U(i, k) = o.init.size()
                    ? (range[k] > 0 ? std::min(std::max((o.init(i, k) - b.low[k]) / range[k], 0.0), 1.0) : 0.0)
                    : uniform01(rng);
  auto to_x = [&]() {
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < d; ++k) X(i, k) = b.low[k] + U(i, k) * range[k];
  };
  to_x();
  Evaluator eval(fun);
  Eigen::VectorXd f(n);
  eval(X, f);
  Eigen::Index bi;
  double bf = f.minCoeff(&bi);
  Eigen::VectorXd bx = X.row(bi).transpose();
  Result r;
  if (o.record_history) r.history.push_back(bf);
  double alpha = o.alpha;
  RowMatrixXd U0(n, d);
  int it = 0;
  for (; it < o.max_iter && !(bf <= o.target); ++it) {
    U0 = U;  // positions at the start of the generation (attractors)
    for (int i = 0; i < n; ++i) {
      bool moved = false;
      for (int j = 0; j < n; ++j) {
        if (!(f[j] < f[i])) continue;
        double r2 = 0.0;
        for (int k = 0; k < d; ++k) { const double dk = U0(j, k) - U(i, k); r2 += dk * dk; }
        const double beta = o.beta0 * std::exp(-o.gamma * r2);
        for (int k = 0; k < d; ++k)
          U(i, k) += beta * (U0(j, k) - U(i, k)) + alpha * (uniform01(rng) - 0.5);
        moved = true;
      }
      if (!moved)  // the brightest firefly walks randomly
        for (int k = 0; k < d; ++k) U(i, k) += alpha * (uniform01(rng) - 0.5);
      for (int k = 0; k < d; ++k) U(i, k) = std::min(std::max(U(i, k), 0.0), 1.0);
    }
    to_x();
    eval(X, f);
    for (int i = 0; i < n; ++i)
      if (f[i] < bf) { bf = f[i]; bx = X.row(i).transpose(); }
    alpha *= o.alpha_decay;
    if (o.record_history) r.history.push_back(bf);
  }
  finish(r, bx, bf, it, eval.evaluations(), o.target);
  return r;
}

}  // namespace bayesgrasp::optim

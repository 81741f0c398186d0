#include "bayesgrasp/optim/trust_region.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

namespace bayesgrasp::optim {

namespace {

struct ResidualEvaluator {
  const BatchResiduals& fun;
  long long n = 0;
  RowMatrixXd operator()(const RowMatrixXd& X) {
    RowMatrixXd R;
    fun(X, R);
    if (R.rows() != X.rows() || R.cols() < 1)
      throw std::invalid_argument("residuals: callback must return an (N, n_residuals) array with n_residuals >= 1");
    n += X.rows();
    return R;
  }
  /// The residuals at one point x.
  Eigen::VectorXd at(const Eigen::VectorXd& x) {
    RowMatrixXd one(1, x.size());
    one.row(0) = x.transpose();
    return (*this)(one).row(0).transpose();
  }
};

// The Jacobian (m x D) of the residuals at x by central differences, one batch of 2D rows.
Eigen::MatrixXd jacobian(ResidualEvaluator& ev, const Eigen::VectorXd& x, double h, Eigen::Index m) {
  const CentralDifferences cd(x, h);
  const RowMatrixXd R = ev(cd.points);
  if (R.cols() != m) throw std::invalid_argument("residuals: number of residuals changed between calls");
  Eigen::MatrixXd J(m, x.size());
  for (Eigen::Index k = 0; k < x.size(); ++k)
    J.col(k) = (R.row(2 * k) - R.row(2 * k + 1)).transpose() / (2.0 * cd.steps[k]);
  return J;
}

// The dogleg step of the model g.p + 1/2 p^T B p inside the trust radius: the full (quasi-)Newton
// step if it fits, else the Cauchy point or the segment towards the Newton step at the radius.
Eigen::VectorXd dogleg(const Eigen::MatrixXd& B, const Eigen::VectorXd& g, double radius) {
  const Eigen::LLT<Eigen::MatrixXd> llt(B);
  const Eigen::VectorXd pb = llt.solve(-g);
  if (pb.norm() <= radius) return pb;
  const double gBg = g.dot(B * g);
  const Eigen::VectorXd pu = -(g.squaredNorm() / gBg) * g;
  if (pu.norm() >= radius) return (radius / pu.norm()) * pu;
  // pu + tau (pb - pu), ||.|| = radius
  const Eigen::VectorXd dp = pb - pu;
  const double a = dp.squaredNorm(), bb = 2.0 * pu.dot(dp), c = pu.squaredNorm() - radius * radius;
  const double tau = (-bb + std::sqrt(bb * bb - 4.0 * a * c)) / (2.0 * a);
  return pu + tau * dp;
}

// BFGS update of B with the step s and gradient change y, skipped unless s.y > 0 (B stays
// positive definite). Before the first update B is scaled to y.y / s.y times the identity
// (Nocedal & Wright, Eq. 6.20).
void bfgs_update(Eigen::MatrixXd& B, const Eigen::VectorXd& s, const Eigen::VectorXd& y, bool& scaled) {
  const double sy = s.dot(y);
  if (!(sy > 1e-12 * s.norm() * y.norm())) return;
  if (!scaled) {
    B = Eigen::MatrixXd::Identity(B.rows(), B.cols()) * (y.squaredNorm() / sy);
    scaled = true;
  }
  const Eigen::VectorXd Bs = B * s;
  B += (y * y.transpose()) / sy - (Bs * Bs.transpose()) / s.dot(Bs);
}

}  // namespace

void validate(const LMOptions& o) {
  require_at_least(o.max_iter, 0, "max_iter");
  require_positive(o.h, "h");
  require_positive(o.lambda0, "lambda0");
  require_non_negative(o.gtol, "gtol");
  require_non_negative(o.xtol, "xtol");
  require_non_negative(o.ftol, "ftol");
}

void validate(const TrustRegionOptions& o) {
  require_at_least(o.max_iter, 0, "max_iter");
  require_positive(o.h, "h");
  require_positive(o.radius0, "radius0");
  if (!(o.max_radius >= o.radius0)) bad_field("max_radius", ">= radius0", number_str(o.max_radius));
  if (!(o.eta >= 0.0 && o.eta < 0.25)) bad_field("eta", "in [0, 0.25)", number_str(o.eta));
  require_non_negative(o.gtol, "gtol");
  require_non_negative(o.xtol, "xtol");
}

Result levenberg_marquardt(const BatchResiduals& fun, const Eigen::VectorXd& x0, const Bounds& b,
                           const LMOptions& o) {
  validate(o);
  validate_start(x0, b, o.h);
  const int d = static_cast<int>(x0.size());
  ResidualEvaluator ev{fun};
  Eigen::VectorXd x = project(x0, b);
  Eigen::VectorXd r = ev.at(x);
  if (!r.allFinite()) throw std::invalid_argument("x0: residuals are not finite at the start point");
  const int m = static_cast<int>(r.size());
  double f = 0.5 * r.squaredNorm();
  Result res;
  if (o.record_history) res.history.push_back(f);
  res.message = "iteration budget used";
  double lambda = -1.0, nu = 2.0;
  bool need_jac = true;
  Eigen::MatrixXd A;
  Eigen::VectorXd g;
  int it = 0;
  for (; it < o.max_iter; ++it) {
    if (f <= o.ftol) { res.converged = true; res.message = "residual below ftol"; break; }
    if (need_jac) {
      const Eigen::MatrixXd J = jacobian(ev, x, o.h, m);
      if (!J.allFinite()) { res.message = "Jacobian is not finite"; break; }
      A = J.transpose() * J;
      g = J.transpose() * r;
      need_jac = false;
      if (lambda < 0.0) lambda = o.lambda0 * std::max(A.diagonal().maxCoeff(), 1e-300);
    }
    if (g.lpNorm<Eigen::Infinity>() < o.gtol) { res.converged = true; res.message = "gradient below gtol"; break; }
    Eigen::MatrixXd Ad = A;
    for (int k = 0; k < d; ++k) Ad(k, k) += lambda * std::max(A(k, k), 1e-12);
    const Eigen::VectorXd dx = Ad.ldlt().solve(-g);
    if (!dx.allFinite()) { res.message = "singular damped normal equations"; break; }
    if (dx.norm() < o.xtol * (x.norm() + o.xtol)) { res.converged = true; res.message = "step below xtol"; break; }
    const Eigen::VectorXd xn = project(x + dx, b);
    const Eigen::VectorXd step = xn - x;
    const Eigen::VectorXd rn = ev.at(xn);
    const double fn = rn.allFinite() ? 0.5 * rn.squaredNorm() : std::numeric_limits<double>::infinity();
    // Predicted reduction of the Gauss-Newton model: -(g.s + 1/2 s^T A s).
    const double pred = -(g.dot(step) + 0.5 * step.dot(A * step));
    const double rho = pred > 0.0 ? (f - fn) / pred : -1.0;
    if (rho > 0.0 && fn < f) {
      x = xn;
      r = rn;
      f = fn;
      need_jac = true;
      lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      nu = 2.0;
    } else {
      lambda *= nu;
      nu *= 2.0;
      if (!std::isfinite(lambda) || lambda > 1e300) { res.message = "damping overflow: no decrease found"; break; }
    }
    if (o.record_history) res.history.push_back(f);
  }
  set_outcome(res, x, f, it, ev.n);
  return res;
}

Result trust_region(const BatchObjective& fun, const Eigen::VectorXd& x0, const Bounds& b,
                    const TrustRegionOptions& o) {
  validate(o);
  validate_start(x0, b, o.h);
  const int d = static_cast<int>(x0.size());
  Evaluator eval(fun);
  Eigen::VectorXd x = project(x0, b);
  double f = start_value(eval, x);
  Eigen::VectorXd g = numerical_gradient(eval, x, o.h);
  Eigen::MatrixXd B = Eigen::MatrixXd::Identity(d, d);
  bool scaled = false;
  double radius = o.radius0;
  Result res;
  if (o.record_history) res.history.push_back(f);
  res.message = "iteration budget used";
  int it = 0;
  for (; it < o.max_iter; ++it) {
    if (g.lpNorm<Eigen::Infinity>() < o.gtol) { res.converged = true; res.message = "gradient below gtol"; break; }
    if (radius < o.xtol * (x.norm() + o.xtol)) { res.converged = true; res.message = "trust radius below xtol"; break; }
    const Eigen::VectorXd xn = project(x + dogleg(B, g, radius), b);
    const Eigen::VectorXd s = xn - x;
    const double fn = eval.at(xn);
    const double pred = -(g.dot(s) + 0.5 * s.dot(B * s));
    const double rho = (pred > 0.0 && std::isfinite(fn)) ? (f - fn) / pred : -1.0;
    if (rho < 0.25) radius = 0.25 * s.norm() > 0 ? 0.25 * s.norm() : 0.25 * radius;
    else if (rho > 0.75 && s.norm() > 0.99 * radius) radius = std::min(2.0 * radius, o.max_radius);
    if (rho > o.eta && fn < f) {
      const Eigen::VectorXd gn = numerical_gradient(eval, xn, o.h);
      bfgs_update(B, s, gn - g, scaled);
      x = xn;
      f = fn;
      g = gn;
    }
    if (o.record_history) res.history.push_back(f);
  }
  set_outcome(res, x, f, it, eval.evaluations());
  return res;
}

}  // namespace bayesgrasp::optim

#include "bayesgrasp/gp/hyperparameter_fit.hpp"

#include <LBFGSB.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace bayesgrasp::gp {

namespace {

struct Box {
  Eigen::VectorXd lb, ub;
};

// Box bounds relative to the data's scales keep L-BFGS-B away from degenerate corners:
// lengthscales in [1e-3, 1e4] x the input's range, variance in [1e-6, 1e6] x and noise in
// [1e-9, 1e2] x the outputs' mean variance; the other entries unbounded.
Box data_box(const Eigen::MatrixXd& Xn, const Eigen::MatrixXd& Yn, Eigen::Index n) {
  const Eigen::Index D = Xn.cols(), P = Yn.cols();
  Box b{Eigen::VectorXd::Constant(n, -1e10), Eigen::VectorXd::Constant(n, 1e10)};
  double yv = 0.0;
  for (Eigen::Index p = 0; p < P; ++p) yv += (Yn.col(p).array() - Yn.col(p).mean()).square().mean();
  yv = yv / P;
  // Outputs constant to round-off (standardised residues ~1e-17, or one point) have no scale of
  // their own: bounds relative to their ~1e-34 "variance" would let the signal variance reach
  // 1e-34. Such data, and data without variance, take the unit scale.
  if (!(yv > 1e-20)) yv = std::max(1e-300, Yn.array().square().mean());
  if (!(yv > 1e-20)) yv = 1.0;
  for (Eigen::Index d = 0; d < D; ++d) {
    const Eigen::ArrayXd c = Xn.col(d).array();
    double range = c.maxCoeff() - c.minCoeff();
    if (!(range > 0.0)) range = 1.0;
    b.lb[d] = std::log(1e-3 * range);
    b.ub[d] = std::log(1e4 * range);
  }
  b.lb[D] = std::log(1e-6 * yv);
  b.ub[D] = std::log(1e6 * yv);
  b.lb[D + 1] = std::log(1e-9 * yv);
  b.ub[D + 1] = std::log(1e2 * yv);
  return b;
}

// The profiled layout drops the log variance (entry D); the log noise entry becomes
// log(noise / variance), bounded by the full box.
Eigen::VectorXd drop_variance(const Eigen::VectorXd& v, Eigen::Index D, double ratio_entry) {
  Eigen::VectorXd out(v.size() - 1);
  out << v.head(D), ratio_entry, v.tail(v.size() - D - 2);
  return out;
}

// The objective as L-BFGS-B sees it: counts evaluations, keeps the best point, and turns a
// failed or non-finite evaluation into a large value with a zero gradient.
struct TrackedObjective {
  TrackedObjective(const GaussianProcess& m, FitObjective k) : model(&m), kind(k) {}
  const GaussianProcess* model;
  FitObjective kind;
  int evals = 0;
  double best_f = std::numeric_limits<double>::infinity();
  Eigen::VectorXd best_x;
  double best_log_scale = 0.0;
  std::string last_error;

  double penalty() const { return std::isfinite(best_f) ? std::abs(best_f) * 10.0 + 1e10 : 1e300; }

  double operator()(const Eigen::VectorXd& t, Eigen::VectorXd& g) {
    ++evals;
    double f, ls = 0.0;
    try {
      f = kind == FitObjective::ProfiledScale ? model->profiled_objective(t, g, &ls) : model->objective(t, g);
    } catch (const std::runtime_error& e) {
      last_error = e.what();
      g.setZero();
      return penalty();
    }
    if (!std::isfinite(f) || !g.allFinite()) {
      g.setZero();
      return penalty();
    }
    if (f < best_f) {
      best_f = f;
      best_x = t;
      best_log_scale = ls;
    }
    return f;
  }
};

LBFGSpp::LBFGSBParam<double> solver_parameters(int max_iter) {
  LBFGSpp::LBFGSBParam<double> param;
  param.m = 10;
  param.epsilon = 1e-5;
  param.epsilon_rel = 0.0;
  param.past = 1;
  param.delta = 2.2e-9;  // scipy's L-BFGS-B default factr = 1e7
  param.max_iterations = max_iter;
  param.max_linesearch = 30;
  return param;
}

}  // namespace

HyperparameterFit fit_hyperparameters(const GaussianProcess& model, const Eigen::VectorXd& theta0,
                                      const Eigen::MatrixXd& Xn, const Eigen::MatrixXd& Yn, int max_iter,
                                      FitObjective objective) {
  const Eigen::Index D = Xn.cols();
  Box box = data_box(Xn, Yn, theta0.size());
  Eigen::VectorXd x = theta0.cwiseMax(box.lb).cwiseMin(box.ub);
  // A start at the noise bound (an initial noise of 0) sits where the gradient in log noise
  // vanishes, and L-BFGS-B stops there; start such a fit from 1e-2 of the output variance.
  if (theta0[D + 1] <= box.lb[D + 1]) x[D + 1] = std::min(box.ub[D + 1], box.lb[D + 1] + std::log(1e7));
  if (objective == FitObjective::ProfiledScale) {
    const Box full = box;
    x = drop_variance(x, D, x[D + 1] - x[D]);
    box.lb = drop_variance(full.lb, D, full.lb[D + 1] - full.ub[D]);
    box.ub = drop_variance(full.ub, D, full.ub[D + 1] - full.lb[D]);
  }
  const LBFGSpp::LBFGSBParam<double> param = solver_parameters(max_iter);  // the solver keeps a reference
  LBFGSpp::LBFGSBSolver<double> solver(param);
  TrackedObjective fn(model, objective);
  HyperparameterFit fit;
  double fx = 0.0;
  try {
    fit.info.iterations = solver.minimize(fn, x, fx, box.lb, box.ub);
    fit.info.message = "converged";
  } catch (const std::exception& e) {
    fit.info.message = std::string("stopped: ") + e.what();
  }
  fit.info.evaluations = fn.evals;
  if (fn.best_x.size() == 0)
    throw std::runtime_error("fit: the log marginal likelihood could not be evaluated at the initial "
                             "hyper-parameters (" + fn.last_error + ")");
  fit.theta = fn.best_x;
  if (objective == FitObjective::ProfiledScale) {  // back to [log lengthscales, log variance, log noise, ...]
    const Eigen::VectorXd& t = fn.best_x;
    fit.theta.resize(t.size() + 1);
    // The profiled scale s* = quad / (N P) is not bounded by the solver: for constant outputs
    // (or one point) it runs to ~1e-300. Keep it, and the noise it implies, inside the box.
    const Box full = data_box(Xn, Yn, theta0.size());
    const double log_scale = std::clamp(fn.best_log_scale, full.lb[D], full.ub[D]);
    const double log_noise = std::clamp(t[D] + log_scale, full.lb[D + 1], full.ub[D + 1]);
    fit.theta << t.head(D), log_scale, log_noise, t.tail(t.size() - D - 1);
  }
  return fit;
}

}  // namespace bayesgrasp::gp

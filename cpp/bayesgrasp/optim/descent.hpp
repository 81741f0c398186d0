// Steepest descent with central-difference gradients and a backtracking (Armijo) line search,
// optionally projected onto a box. Also the numerical gradient shared by the local optimisers.
#pragma once

#include "bayesgrasp/optim/objective.hpp"

namespace bayesgrasp::optim {

/// The central-difference stencil around x: rows 2k and 2k + 1 of `points` are x + h_k e_k and
/// x - h_k e_k, with the step h_k = h * max(1, |x_k|) in `steps`.
struct CentralDifferences {
  RowMatrixXd points;     ///< (2D, D)
  Eigen::VectorXd steps;  ///< (D,)
  CentralDifferences(const Eigen::VectorXd& x, double h);
};

/// The gradient by central differences, the stencil evaluated as one batch of 2D rows.
Eigen::VectorXd numerical_gradient(Evaluator& eval, const Eigen::VectorXd& x, double h);

struct DescentOptions {
  int max_iter = 500;
  double h = 1e-6;           ///< relative finite-difference step
  double t0 = 1.0;           ///< first trial step length (later: twice the last accepted one)
  double armijo = 1e-4;      ///< sufficient-decrease constant c in f(x+) <= f(x) - c g.(x - x+)
  double backtrack = 0.5;    ///< step shrink factor in (0, 1)
  int max_backtrack = 40;
  double gtol = 1e-8;        ///< stop when the (projected) gradient's max-norm is below gtol
  double ftol = 1e-14;       ///< stop when the relative decrease is below ftol
  bool record_history = false;
};

/// bounds may be empty (size-0 vectors): unconstrained. With bounds, x0 is clipped into the box
/// and every trial point projected onto it.
/// Throws std::invalid_argument naming the first bad field.
void validate(const DescentOptions& o);

Result steepest_descent(const BatchObjective& fun, const Eigen::VectorXd& x0, const Bounds& bounds,
                        const DescentOptions& opt = {});

/// Clips x into the box (no-op for empty bounds).
Eigen::VectorXd project(const Eigen::VectorXd& x, const Bounds& b);
/// Checks x0 is finite and matches the bounds' dimension (if any), non-empty bounds, and the
/// relative finite-difference step h > 0: what every local optimiser needs.
void validate_start(const Eigen::VectorXd& x0, const Bounds& b, double h);
/// The objective at the start point x; throws std::invalid_argument (naming x0) if not finite.
double start_value(Evaluator& eval, const Eigen::VectorXd& x);

}  // namespace bayesgrasp::optim

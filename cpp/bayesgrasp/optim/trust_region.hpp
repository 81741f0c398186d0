// Local optimisers for the pose update of Pub. VI (Eq. 4.4):
//  * Levenberg-Marquardt for least squares, f(x) = 1/2 ||r(x)||^2, with a central-difference
//    Jacobian evaluated as one batch, Marquardt's diagonal scaling and Nielsen's damping update;
//  * a dogleg trust region on a scalar objective with central-difference gradients and a BFGS
//    Hessian approximation (for objectives that are not sums of squares, e.g. a negative log
//    GP predictive density plus a Gaussian prior).
#pragma once

#include "bayesgrasp/optim/descent.hpp"

namespace bayesgrasp::optim {

struct LMOptions {
  int max_iter = 200;
  double h = 1e-6;          ///< relative finite-difference step
  double lambda0 = 1e-3;    ///< initial damping, relative to max diag(J^T J)
  double gtol = 1e-10;      ///< stop when max |J^T r| < gtol
  double xtol = 1e-12;      ///< stop when ||dx|| < xtol (||x|| + xtol)
  double ftol = 1e-15;      ///< stop when f < ftol (an exact fit)
  bool record_history = false;
};

/// Throws std::invalid_argument naming the first bad field.
void validate(const LMOptions& o);

/// Minimises 1/2 ||r(x)||^2; residual callback sizes R to (N, n_residuals). Trial points are
/// projected onto the box if bounds are given (non-empty).
Result levenberg_marquardt(const BatchResiduals& residuals, const Eigen::VectorXd& x0,
                           const Bounds& bounds, const LMOptions& opt = {});

struct TrustRegionOptions {
  int max_iter = 200;
  double h = 1e-6;          ///< relative finite-difference step
  double radius0 = 1.0;     ///< initial trust radius
  double max_radius = 1e6;
  double eta = 1e-4;        ///< accept a step when actual/predicted reduction > eta
  double gtol = 1e-8;       ///< stop when the gradient's max-norm < gtol
  double xtol = 1e-12;      ///< stop when the trust radius < xtol (||x|| + xtol)
  bool record_history = false;
};

/// Throws std::invalid_argument naming the first bad field.
void validate(const TrustRegionOptions& o);

/// Dogleg trust region with BFGS updates (skipped when s.y <= 0, so the model stays convex).
Result trust_region(const BatchObjective& fun, const Eigen::VectorXd& x0, const Bounds& bounds,
                    const TrustRegionOptions& opt = {});

}  // namespace bayesgrasp::optim

// The FITC log marginal likelihood and its gradient (Snelson & Ghahramani 2006), the objective
// of SparseGP. Notation: Kmn = k(Z, X) (M x N), L = chol(Kmm + jitter), V = L^-1 Kmn,
// lam = diag(Knn - V^T V) + noise, A = I + V diag(1/lam) V^T = L^-1 B L^-T, LA = chol(A).
// The O(N M^2) work is BLAS level 3 (blas.hpp): V (TRMM with the explicit M x M triangular
// inverse, N M^2), A (SYRK, N M^2), A^-1 V (GEMM, 2 N M^2), L^-T (dL/dV) (TRMM, N M^2),
// V diag(w) V^T (two SYRKs over the columns of either sign of w, N M^2): 6 N M^2 flops;
// nothing N x N. The whitened form (A >= I) keeps lam and the gradient accurate when Kmm is
// ill-conditioned, where a Kmm^-1 / B^-1 form of the same cost gives noisy gradients that stall
// L-BFGS. Internal to the gp concept.
#pragma once

#include <Eigen/Core>

#include "bayesgrasp/gp/gaussian_process.hpp"
#include "bayesgrasp/gp/kernel.hpp"

namespace bayesgrasp::gp::detail {

/// The data and hyper-parameters of one evaluation (standardised units).
struct FitcInputs {
  const Eigen::MatrixXd& Xn;   ///< (N, D) training inputs
  const Eigen::MatrixXd& Yn;   ///< (N, P) training outputs
  const Eigen::MatrixXd& Zn;   ///< (M, D) inducing inputs
  const Kernel& kernel;
  double noise;
  const Eigen::VectorXd& mean_constant;  ///< (P,)
  double jitter0;              ///< initial relative jitter of Kmm
  MeanType mean;               ///< Constant: the gradient has the mean constants' entries
};

/// Which gradient an evaluation computes.
enum class FitcGradient {
  None,
  Hyperparameters,             ///< [log lengthscales, log variance, log noise, mean constants]
  HyperparametersAndInducing,  ///< ... followed by the inducing inputs (M*D, column-major)
};

struct FitcEval {
  Eigen::MatrixXd L, LA;
  Eigen::MatrixXd beta;  ///< (M, P) LA^-1 V diag(1/lam) (y - c)
  double lml = 0.0;
  double jitter = 0.0;   ///< the relative jitter that made chol(Kmm) succeed
};

/// One evaluation; fills *grad (of the log marginal likelihood's negative) unless `what` is None.
/// With profile_log_scale non-null the signal scale is profiled out (GPOptions::profile_scale):
/// the likelihood and gradient are those at the optimal scale, whose log is stored there.
FitcEval fitc_eval(const FitcInputs& in, FitcGradient what, Eigen::VectorXd* grad,
                   double* profile_log_scale = nullptr);

}  // namespace bayesgrasp::gp::detail

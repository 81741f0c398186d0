// Prediction of a fitted GP from its cache: every model (ExactGP, SparseGP) reduces to
//   mean_p(x) = offset_p + sum_k alpha_kp f_k(x),    var_f,p(x) = var_f0,p (1 - |h(x)|^2),
// with f(x) = shape(r2(x, basis_k)) the kernel vector between x and M basis inputs (the training
// inputs or the inducing inputs) and h = G f or G^-1 f for a triangular variance factor G.
// Batches of inputs run through SIMD kernels that fuse the kernel vectors, the weighted sums and
// the quadratic form (prediction_kernels.hpp); all functions are const and thread-safe.
#pragma once

#include <Eigen/Core>

#include <vector>

#include "bayesgrasp/gp/kernel.hpp"

namespace bayesgrasp::gp {

/// What a predictive variance, covariance or sample describes.
enum class Predictive {
  Latent,       ///< the latent function f
  Observation,  ///< an observation y = f + noise
};

/// How the variance factor G turns a kernel vector f into h, var_f = var_f0 (1 - |h|^2).
enum class VarianceFactor {
  Upper,         ///< h = G f, G upper triangular (SparseGP; packed for the fused kernel)
  InverseLower,  ///< h = G^-1 f, G lower triangular: a triangular solve per block (ExactGP)
};

/// A fitted model's scaled basis, weights and variance factor, in raw input and output units.
struct PredictionCache {
  KernelType type = KernelType::SquaredExponential;
  Eigen::VectorXd inv_ls;       ///< (D,) 1 / lengthscale in raw input units
  Eigen::MatrixXd basis;        ///< (M, D) basis inputs times inv_ls
  Eigen::MatrixXd alpha;        ///< (M, P) weights in raw output units (include the variance)
  Eigen::RowVectorXd offset;    ///< (P,)
  Eigen::MatrixXd G;            ///< (M, M) variance factor, applied as `factor` says
  VarianceFactor factor = VarianceFactor::Upper;
  Eigen::RowVectorXd var_f0;    ///< (P,) prior variance per output in raw units
  Eigen::RowVectorXd noise;     ///< (P,) noise variance per output in raw units
  /// G (factor Upper) packed in register tiles for the fused mean + variance kernel
  /// (pack_factor()); empty = the blockwise Eigen path.
  std::vector<double> G_packed;

  /// Packs an upper-triangular G for the fused prediction kernel: the per-input quadratic form
  /// |G f|^2 then costs M^2 flops in registers, computed on batches of inputs right after their
  /// kernel vectors, with no (N x M) intermediate. Clears G_packed for any other factor.
  void pack_factor();
};

/// Batches of at least this many inputs are split over the requested threads.
constexpr long kParallelPredictionMin = 2048;

/// Predictive mean (N, P) at the rows of X (raw units; X checked by the caller).
Eigen::MatrixXd predict_mean(const PredictionCache& c, const Eigen::MatrixXd& X, int threads);

/// Predictive mean and variance, each (N, P); the variance of f, plus the noise for Observation.
void predict_mean_var(const PredictionCache& c, const Eigen::MatrixXd& X, Predictive what, int threads,
                      Eigen::MatrixXd& mean, Eigen::MatrixXd& var);

/// Predictive covariance (N, N) of one output at the rows of X (plus the noise on the diagonal
/// for Observation).
Eigen::MatrixXd predict_cov(const PredictionCache& c, const Eigen::MatrixXd& X, int output, Predictive what);

}  // namespace bayesgrasp::gp

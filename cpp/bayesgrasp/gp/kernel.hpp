// Stationary ARD covariance functions for the GP models: squared exponential and Matern 5/2.
//
//   k(a, b) = variance * f(r2),   r2 = sum_d ((a_d - b_d) / lengthscale_d)^2
//   SE:         f(r2) = exp(-r2 / 2)
//   Matern 5/2: f(r2) = (1 + sqrt(5 r2) + 5 r2 / 3) exp(-sqrt(5 r2))
//
// Inputs are rows of an (N, D) matrix. The hyper-parameters are kept in log space for
// optimisation (log lengthscales, log signal variance).
#pragma once

#include <Eigen/Core>

#include <string>

namespace bayesgrasp::gp {

enum class KernelType { SquaredExponential, Matern52 };

/// "se" (also "rbf", "squared_exponential") or "matern52"; throws std::invalid_argument otherwise.
KernelType kernel_type_from_string(const std::string& name);
std::string kernel_type_name(KernelType type);

struct Kernel {
  KernelType type = KernelType::SquaredExponential;
  Eigen::VectorXd log_lengthscale;  ///< (D,) log of the ARD lengthscales
  double log_variance = 0.0;        ///< log of the signal variance

  Kernel() = default;
  Kernel(KernelType t, const Eigen::VectorXd& lengthscale, double variance);

  int dim() const { return static_cast<int>(log_lengthscale.size()); }
  Eigen::VectorXd lengthscale() const { return log_lengthscale.array().exp(); }
  double variance() const;
  /// Throws std::invalid_argument unless lengthscales and variance are positive and finite.
  void validate() const;

  /// f(r2) elementwise (without the variance factor), in place.
  void shape_inplace(Eigen::Ref<Eigen::MatrixXd> r2) const;

  /// Covariance matrix K(A, B): (A.rows(), B.rows()).
  Eigen::MatrixXd operator()(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) const;
  /// Symmetric K(A, A).
  Eigen::MatrixXd operator()(const Eigen::MatrixXd& A) const;
};

namespace detail {
/// Squared scaled distances between the rows of As (Na x D) and Bs (Nb x D) (inputs already
/// divided by the lengthscales): (Na x Nb), computed directly (no |a|^2+|b|^2-2ab cancellation).
Eigen::MatrixXd sq_dist(const Eigen::MatrixXd& As, const Eigen::MatrixXd& Bs);

/// Contracts G (dL/dK, Na x Nb, K = k(A, B)) with the kernel's derivatives.
/// As, Bs: scaled inputs (Na x D, Nb x D); R2: squared scaled distances; K: the kernel matrix
/// (with the variance). Adds dL/dlog_lengthscale to g_logls (D), dL/dlog_variance to *g_logvar
/// and, if non-null, dL/dA to *gA (Na x D) and dL/dB to *gB (Nb x D), in unscaled coordinates.
void contract_gradient(const Kernel& k, const Eigen::MatrixXd& As, const Eigen::MatrixXd& Bs,
                       const Eigen::Ref<const Eigen::MatrixXd>& R2, const Eigen::Ref<const Eigen::MatrixXd>& K,
                       const Eigen::Ref<const Eigen::MatrixXd>& G,
                       Eigen::VectorXd& g_logls, double* g_logvar, Eigen::MatrixXd* gA,
                       Eigen::MatrixXd* gB);
}  // namespace detail

}  // namespace bayesgrasp::gp

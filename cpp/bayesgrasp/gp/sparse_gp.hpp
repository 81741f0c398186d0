// Sparse GP regression with the FITC approximation (Snelson & Ghahramani 2006):
//   p(y) = N(0, Q_nn + diag(K_nn - Q_nn) + noise I),  Q_nn = K_nm K_mm^-1 K_mn,
// with M inducing inputs Z (k-means++ initialised, kmeans.hpp; optionally optimised). One
// objective and gradient evaluation (fitc.hpp) costs O(N M^2) through Cholesky factors of M x M
// matrices only. The common interface is in gaussian_process.hpp.
#pragma once

#include "bayesgrasp/gp/gaussian_process.hpp"

namespace bayesgrasp::gp {

class SparseGP : public GaussianProcess {
 public:
  explicit SparseGP(GPOptions options = {});
  void fit(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) override;
  double objective(const Eigen::VectorXd& theta, Eigen::VectorXd& grad) const override;
  Eigen::VectorXd parameters() const override;
  bool supports_profile() const override { return true; }
  double profiled_objective(const Eigen::VectorXd& theta_p, Eigen::VectorXd& grad, double* log_scale) const override;

  /// Inducing inputs (M, D) in input units.
  Eigen::MatrixXd inducing_inputs() const;
  int n_inducing() const { return static_cast<int>(Zn_.rows()); }

 private:
  void build_cache();
  Eigen::MatrixXd Zn_;  // (M, D) standardised
};

}  // namespace bayesgrasp::gp

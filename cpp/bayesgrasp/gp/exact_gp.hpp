// Exact GP regression: O(N^3) Cholesky of K + noise I (with adaptive jitter, linalg.hpp) and
// analytic log-marginal-likelihood gradients; predictions solve with the Cholesky factor.
// The common interface is in gaussian_process.hpp.
#pragma once

#include "bayesgrasp/gp/gaussian_process.hpp"

namespace bayesgrasp::gp {

class ExactGP : public GaussianProcess {
 public:
  explicit ExactGP(GPOptions options = {});
  void fit(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) override;
  double objective(const Eigen::VectorXd& theta, Eigen::VectorXd& grad) const override;

 private:
  void build_cache();
};

}  // namespace bayesgrasp::gp

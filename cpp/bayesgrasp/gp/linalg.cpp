#include "bayesgrasp/gp/linalg.hpp"

#include <Eigen/Cholesky>

#include <cmath>
#include <stdexcept>
#include <string>

#include "bayesgrasp/gp/blas.hpp"

namespace bayesgrasp::gp {

Eigen::MatrixXd robust_cholesky(const Eigen::MatrixXd& A, double jitter0, double scale, const char* what,
                                double* used, double max_jitter) {
  if (!A.allFinite()) throw std::runtime_error(std::string(what) + ": matrix has NaN or infinity");
  if (!(scale > 0.0) || !std::isfinite(scale)) scale = 1.0;
  double j = jitter0;
  Eigen::LLT<Eigen::MatrixXd> llt;
  for (;;) {
    if (j == 0.0) {
      llt.compute(A);
    } else {
      Eigen::MatrixXd Aj = A;
      Aj.diagonal().array() += j * scale;
      llt.compute(Aj);
    }
    if (llt.info() == Eigen::Success) {
      Eigen::MatrixXd L = llt.matrixL();
      if (L.diagonal().allFinite() && (L.diagonal().array() > 0.0).all()) {
        if (used) *used = j;
        return L;
      }
    }
    j = (j == 0.0) ? 1e-10 : j * 10.0;
    if (j > max_jitter * (1.0 + 1e-9))
      throw std::runtime_error(std::string(what) +
                               ": Cholesky failed even with jitter; the covariance is not positive "
                               "definite (duplicated inputs with zero noise, or extreme hyper-parameters)");
  }
}

Eigen::MatrixXd lower_triangular_inverse(const Eigen::MatrixXd& L) {
  Eigen::MatrixXd Linv = Eigen::MatrixXd::Identity(L.rows(), L.rows());
  blas::trsm_left(blas::Triangle::Lower, blas::Op::None, L, Linv);
  return Linv;
}

Eigen::MatrixXd inverse_from_cholesky(const Eigen::MatrixXd& L) {
  Eigen::MatrixXd Ainv = lower_triangular_inverse(L);
  blas::trsm_left(blas::Triangle::Lower, blas::Op::Transpose, L, Ainv);
  return Ainv;
}

}  // namespace bayesgrasp::gp

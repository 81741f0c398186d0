// Dense linear algebra of the GP models: Cholesky factorisation with adaptive jitter and the
// explicit inverses built from triangular factors by BLAS triangular solves (blas.hpp).
#pragma once

#include <Eigen/Core>

namespace bayesgrasp::gp {

/// Cholesky with adaptive jitter: tries A + jitter*scale*I for jitter = jitter0, then 1e-10 (if
/// jitter0 is 0), x10, ... up to max_jitter; returns the lower factor and sets *used. Throws
/// std::runtime_error (naming `what`) if it never succeeds or A is not finite.
Eigen::MatrixXd robust_cholesky(const Eigen::MatrixXd& A, double jitter0, double scale, const char* what,
                                double* used = nullptr, double max_jitter = 1e-2);

/// L^-1 for a lower-triangular L (M x M), by one triangular solve against the identity.
Eigen::MatrixXd lower_triangular_inverse(const Eigen::MatrixXd& L);

/// A^-1 = L^-T L^-1 from the lower Cholesky factor L of A, by two triangular solves.
Eigen::MatrixXd inverse_from_cholesky(const Eigen::MatrixXd& L);

}  // namespace bayesgrasp::gp

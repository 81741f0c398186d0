// Thin wrappers over the reference BLAS interface (Fortran symbols; linked against Debian's
// OpenBLAS) for the few large dense products of the FITC objective. Column-major Eigen
// matrices or blocks in, sizes checked; each call is one BLAS level-3 routine.
//
// Why not Eigen's own products: on the machines we measure (AMD EPYC, AVX-512 double-pumped)
// OpenBLAS's GEMM runs about 1.25x faster than Eigen's, and BLAS has the triangular (TRMM) and
// symmetric rank-k (SYRK) products at the rate of its GEMM, which Eigen's TRMM does not reach.
// EIGEN_USE_BLAS would do the same for every product of every target, including small ones in
// threaded batch loops; these wrappers keep the change to the code that needs it.
#pragma once

#include <Eigen/Core>

namespace bayesgrasp::gp::blas {

using MatRef = Eigen::Ref<Eigen::MatrixXd>;
using ConstMatRef = Eigen::Ref<const Eigen::MatrixXd>;

/// C = alpha op(A) op(B) + beta C, op(X) = X or X^T (ta, tb).
void gemm(bool ta, bool tb, double alpha, const ConstMatRef& A, const ConstMatRef& B, double beta, MatRef C);

/// Lower triangle of C = alpha A A^T + beta C (A: n x k); the strict upper triangle is left alone.
void syrk_lower(double alpha, const ConstMatRef& A, double beta, MatRef C);

/// B = op(T) B in place, T square triangular (lower if `lower`, op = transpose if `trans`);
/// only T's triangle is read.
void trmm_left(bool lower, bool trans, const ConstMatRef& T, MatRef B);

/// B = op(T)^-1 B in place (triangular solve with many right-hand sides), T as in trmm_left.
void trsm_left(bool lower, bool trans, const ConstMatRef& T, MatRef B);

}  // namespace bayesgrasp::gp::blas

// Thin wrappers over the reference BLAS interface (Fortran symbols; linked against Debian's
// OpenBLAS) for the few large dense products of the FITC objective. Column-major Eigen
// matrices or blocks in, sizes checked; each call is one BLAS level-3 routine.
//
// Why not Eigen's own products: OpenBLAS's GEMM is faster than Eigen's on the machines we
// measure (BENCHMARKS.md, bench_gp's BM_dgemm_*), and BLAS has the triangular (TRMM) and
// symmetric rank-k (SYRK) products at the rate of its GEMM, which Eigen's TRMM does not reach.
// EIGEN_USE_BLAS would do the same for every product of every target, including small ones in
// threaded batch loops; these wrappers keep the change to the code that needs it.
#pragma once

#include <Eigen/Core>

namespace bayesgrasp::gp::blas {

using MatRef = Eigen::Ref<Eigen::MatrixXd>;
using ConstMatRef = Eigen::Ref<const Eigen::MatrixXd>;

/// op(X) = X or X^T.
enum class Op { None, Transpose };
/// Which triangle of a square matrix holds a triangular factor.
enum class Triangle { Lower, Upper };

/// C = alpha op_a(A) op_b(B) + beta C.
void gemm(Op op_a, Op op_b, double alpha, const ConstMatRef& A, const ConstMatRef& B, double beta, MatRef C);

/// Lower triangle of C = alpha A A^T + beta C (A: n x k); the strict upper triangle is left alone.
void syrk_lower(double alpha, const ConstMatRef& A, double beta, MatRef C);

/// B = op(T) B in place, T square triangular (its `triangle` is read, the other is not).
void trmm_left(Triangle triangle, Op op, const ConstMatRef& T, MatRef B);

/// B = op(T)^-1 B in place (triangular solve with many right-hand sides), T as in trmm_left.
void trsm_left(Triangle triangle, Op op, const ConstMatRef& T, MatRef B);

}  // namespace bayesgrasp::gp::blas

#include "bayesgrasp/gp/blas.hpp"

#include <climits>
#include <stdexcept>
#include <string>

extern "C" {
void dgemm_(const char* ta, const char* tb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
            const int* ldc);
void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha, const double* a,
            const int* lda, const double* beta, double* c, const int* ldc);
void dtrmm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb);
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb);
}

namespace bayesgrasp::gp::blas {

namespace {
int as_int(Eigen::Index v, const char* what) {
  if (v < 0 || v > INT_MAX) throw std::length_error(std::string("blas: ") + what + " does not fit a BLAS int");
  return static_cast<int>(v);
}
int ld(const ConstMatRef& a) { return as_int(std::max<Eigen::Index>(1, a.outerStride()), "leading dimension"); }
int ld(const MatRef& a) { return as_int(std::max<Eigen::Index>(1, a.outerStride()), "leading dimension"); }
}  // namespace

void gemm(Op op_a, Op op_b, double alpha, const ConstMatRef& A, const ConstMatRef& B, double beta, MatRef C) {
  const bool ta = op_a == Op::Transpose, tb = op_b == Op::Transpose;
  const Eigen::Index m = ta ? A.cols() : A.rows(), k = ta ? A.rows() : A.cols();
  const Eigen::Index kb = tb ? B.cols() : B.rows(), n = tb ? B.rows() : B.cols();
  if (k != kb || C.rows() != m || C.cols() != n) throw std::invalid_argument("blas::gemm: size mismatch");
  if (m == 0 || n == 0) return;
  if (k == 0) {
    C *= beta;
    return;
  }
  const int im = as_int(m, "rows"), in = as_int(n, "cols"), ik = as_int(k, "depth");
  const int lda = ld(A), ldb = ld(B), ldc = ld(C);
  dgemm_(ta ? "T" : "N", tb ? "T" : "N", &im, &in, &ik, &alpha, A.data(), &lda, B.data(), &ldb, &beta, C.data(), &ldc);
}

void syrk_lower(double alpha, const ConstMatRef& A, double beta, MatRef C) {
  if (C.rows() != A.rows() || C.cols() != A.rows()) throw std::invalid_argument("blas::syrk_lower: size mismatch");
  if (A.rows() == 0) return;
  const int n = as_int(A.rows(), "rows"), k = as_int(A.cols(), "cols");
  const int lda = ld(A), ldc = ld(C);
  dsyrk_("L", "N", &n, &k, &alpha, A.data(), &lda, &beta, C.data(), &ldc);
}

namespace {
// dtrmm_ and dtrsm_ share their signature: B = op(T) B or op(T)^-1 B, T on the left.
using TriangularLeft = void (*)(const char*, const char*, const char*, const char*, const int*, const int*,
                                const double*, const double*, const int*, double*, const int*);
void triangular_left(TriangularLeft routine, const char* what, Triangle triangle, Op op, const ConstMatRef& T,
                     MatRef B) {
  if (T.rows() != T.cols() || T.rows() != B.rows())
    throw std::invalid_argument(std::string("blas::") + what + ": size mismatch");
  if (B.rows() == 0 || B.cols() == 0) return;
  const int m = as_int(B.rows(), "rows"), n = as_int(B.cols(), "cols");
  const int lda = ld(T), ldb = ld(B);
  const double one = 1.0;
  const char* uplo = triangle == Triangle::Lower ? "L" : "U";
  const char* trans = op == Op::Transpose ? "T" : "N";
  routine("L", uplo, trans, "N", &m, &n, &one, T.data(), &lda, B.data(), &ldb);
}
}  // namespace

void trmm_left(Triangle triangle, Op op, const ConstMatRef& T, MatRef B) {
  triangular_left(dtrmm_, "trmm_left", triangle, op, T, B);
}

void trsm_left(Triangle triangle, Op op, const ConstMatRef& T, MatRef B) {
  triangular_left(dtrsm_, "trsm_left", triangle, op, T, B);
}

}  // namespace bayesgrasp::gp::blas

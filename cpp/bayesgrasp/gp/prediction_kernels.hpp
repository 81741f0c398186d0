// The SIMD building blocks of the fused GP prediction (prediction.cpp): kernel vectors of a
// group of inputs, the weighted sums of the mean and the quadratic form |G f|^2 of the variance
// with a packed upper-triangular G, accumulated in registers. Internal to the gp concept.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <vector>

#include "bayesgrasp/gp/prediction.hpp"
#include "bayesgrasp/gp/vector_exp.hpp"

namespace bayesgrasp::gp::detail {

// Inputs are processed in groups of kGroup: their kernel vectors F (M x kGroup, row k holds
// f_k for the group's inputs, contiguous) are built in a small buffer, then the mean and
// q_j = |G f_j|^2 are accumulated in registers: for a tile of kMR rows of G, H(tile, group) =
// G(tile, k >= i0) F(k >= i0, group) and q += H^2, without storing H. That is M^2 flops per
// input (multiply-adds over the upper triangle), the same arithmetic as Eigen's TRMM but with
// the reduction fused and no (n x M) matrices beyond the L1/L2-sized buffer.
#if defined(__AVX512F__)
constexpr int kNV = 3, kMR = 8;   // 24 accumulators of 32 zmm registers (the tile shape
                                  // chosen by bench_gp among 4x6, 2x8, 3x7, 3x9, 2x12)
#elif defined(__AVX__)
constexpr int kNV = 3, kMR = 4;   // 12 of 16 ymm
#else
constexpr int kNV = 3, kMR = 4;   // 12 of 16 xmm
#endif
constexpr int kGroup = kW * kNV;

// Packed layout of an upper-triangular M x M factor G: tile t covers rows i0 = t*kMR ..
// i0+kMR-1 (rows >= M are zero padding) and columns k = i0 .. M-1; entry (ii, k) sits at
// offset(t) + (k - i0) * kMR + ii. offset(t) = kMR * sum_{s<t} (M - s*kMR).
inline std::vector<double> pack_upper(const Eigen::MatrixXd& G) {
  const Eigen::Index M = G.rows();
  std::vector<double> a;
  for (Eigen::Index i0 = 0; i0 < M; i0 += kMR)
    for (Eigen::Index k = i0; k < M; ++k)
      for (int ii = 0; ii < kMR; ++ii) {
        const Eigen::Index i = i0 + ii;
        a.push_back(i < M && k >= i ? G(i, k) : 0.0);
      }
  return a;
}

// Kernel vectors of up to kGroup inputs (rows i0 .. i0+n-1 of X; a short group repeats its last
// input) into F (M x kGroup, row-major).
inline void shape_group(const PredictionCache& c, const Eigen::MatrixXd& X, Eigen::Index i0, int n, double* F) {
  const Eigen::Index M = c.basis.rows(), D = c.basis.cols();
  constexpr int kMaxD = 16;
  const bool se = c.type == KernelType::SquaredExponential;
  if (D <= kMaxD) {
    alignas(64) double xs[kMaxD][kGroup];
    for (Eigen::Index d = 0; d < D; ++d)
      for (int j = 0; j < kGroup; ++j) xs[d][j] = X(i0 + std::min(j, n - 1), d) * c.inv_ls[d];
    for (Eigen::Index k = 0; k < M; ++k) {
      double* f = F + k * kGroup;
      vd r[kNV];
      for (int v = 0; v < kNV; ++v) r[v] = vbroadcast(0.0);
      for (Eigen::Index d = 0; d < D; ++d) {
        const vd b = vbroadcast(c.basis(k, d));
        for (int v = 0; v < kNV; ++v) {
          const vd t = b - vload(&xs[d][v * kW]);
          r[v] += t * t;
        }
      }
      if (se)
        for (int v = 0; v < kNV; ++v) vstore(f + v * kW, exp_nonpositive(vbroadcast(-0.5) * r[v]));
      else
        for (int v = 0; v < kNV; ++v) vstore(f + v * kW, r[v]);
    }
    if (se) return;
  } else {
    for (Eigen::Index k = 0; k < M; ++k)
      for (int j = 0; j < kGroup; ++j) {
        const Eigen::Index i = i0 + std::min(j, n - 1);
        double s = 0.0;
        for (Eigen::Index d = 0; d < D; ++d) {
          const double t = c.basis(k, d) - X(i, d) * c.inv_ls[d];
          s += t * t;
        }
        F[k * kGroup + j] = s;
      }
  }
  Eigen::Map<Eigen::ArrayXd> a(F, M * kGroup);
  if (se) {
    for (Eigen::Index i = 0; i < M * kGroup; i += kW) vstore(F + i, exp_nonpositive(vbroadcast(-0.5) * vload(F + i)));
  } else {
    const Eigen::ArrayXd s = (5.0 * a).sqrt();
    a = (1.0 + s + s.square() * (1.0 / 3.0)) * (-s).exp();
  }
}

// Mean of one output for a group, SE kernel, D <= 16: the kernel values are summed into the
// mean as they are made, never stored (the M x kGroup buffer does not fit L1 at M = 200).
// Returns false (nothing written) when the case is not covered.
inline bool mean_group_se(const PredictionCache& c, const Eigen::MatrixXd& X, Eigen::Index i0, int n, const double* alpha,
                   double* m) {
  constexpr int kMaxD = 16;
  const Eigen::Index M = c.basis.rows(), D = c.basis.cols();
  if (c.type != KernelType::SquaredExponential || D > kMaxD) return false;
  // inputs and basis scaled by sqrt(1/2): the accumulated -|b - x|^2 is the exponent itself
  constexpr double kRootHalf = 0.70710678118654752440;
  alignas(64) double xs[kMaxD][kGroup];
  for (Eigen::Index d = 0; d < D; ++d)
    for (int j = 0; j < kGroup; ++j) xs[d][j] = X(i0 + std::min(j, n - 1), d) * (c.inv_ls[d] * kRootHalf);
  vd acc[kNV];
  for (int v = 0; v < kNV; ++v) acc[v] = vbroadcast(0.0);
  for (Eigen::Index k = 0; k < M; ++k) {
    vd e[kNV];
    for (int v = 0; v < kNV; ++v) e[v] = vbroadcast(0.0);
    for (Eigen::Index d = 0; d < D; ++d) {
      const vd b = vbroadcast(c.basis(k, d) * kRootHalf);
      for (int v = 0; v < kNV; ++v) {
        const vd t = b - vload(&xs[d][v * kW]);
        e[v] -= t * t;
      }
    }
    const vd a = vbroadcast(alpha[k]);
    for (int v = 0; v < kNV; ++v) acc[v] += a * exp_nonpositive(e[v]);
  }
  for (int v = 0; v < kNV; ++v) vstore(m + v * kW, acc[v]);
  return true;
}

// q[j] = |G f_j|^2 for the group's F, G packed by pack_upper.
inline void quad_group(const double* Gp, Eigen::Index M, const double* F, double* q) {
  vd qa[kNV];
  for (int v = 0; v < kNV; ++v) qa[v] = vbroadcast(0.0);
  const double* a = Gp;
  for (Eigen::Index i0 = 0; i0 < M; i0 += kMR) {
    vd acc[kMR][kNV];
    for (int ii = 0; ii < kMR; ++ii)
      for (int v = 0; v < kNV; ++v) acc[ii][v] = vbroadcast(0.0);
    for (Eigen::Index k = i0; k < M; ++k, a += kMR) {
      const double* f = F + k * kGroup;
      vd fv[kNV];
      for (int v = 0; v < kNV; ++v) fv[v] = vload(f + v * kW);
      for (int ii = 0; ii < kMR; ++ii) {
        const vd b = vbroadcast(a[ii]);
        for (int v = 0; v < kNV; ++v) acc[ii][v] += b * fv[v];
      }
    }
    for (int ii = 0; ii < kMR; ++ii)
      for (int v = 0; v < kNV; ++v) qa[v] += acc[ii][v] * acc[ii][v];
  }
  for (int v = 0; v < kNV; ++v) vstore(q + v * kW, qa[v]);
}

// mean[j] = sum_k alpha(k) F(k, j) for one output column.
inline void mean_group(const double* alpha, Eigen::Index M, const double* F, double* m) {
  vd acc[kNV];
  for (int v = 0; v < kNV; ++v) acc[v] = vbroadcast(0.0);
  for (Eigen::Index k = 0; k < M; ++k) {
    const vd b = vbroadcast(alpha[k]);
    for (int v = 0; v < kNV; ++v) acc[v] += b * vload(F + k * kGroup + v * kW);
  }
  for (int v = 0; v < kNV; ++v) vstore(m + v * kW, acc[v]);
}

}  // namespace bayesgrasp::gp::detail

#include "bayesgrasp/gp/fitc.hpp"

#include <algorithm>
#include <cmath>

#include "bayesgrasp/gp/blas.hpp"
#include "bayesgrasp/gp/linalg.hpp"
#include "bayesgrasp/gp/vector_exp.hpp"
#include "bayesgrasp/gp/workspace.hpp"

namespace bayesgrasp::gp::detail {

namespace {
constexpr double kLog2Pi = 1.8378770664093453;
using blas::Op;
using blas::Triangle;

// Per-thread workspace: the M x N matrices are reused between evaluations (workspace.hpp).
struct FitcWork {
  Workspace Kmn, R2mn, V, S, T;
};

// The terms of one evaluation, in the order the steps below make them.
struct FitcTerms {
  FitcTerms(FitcWork& work, const FitcInputs& inputs, bool gradient)
      : ws(work),
        in(inputs),
        N(inputs.Xn.rows()),
        P(inputs.Yn.cols()),
        D(inputs.Xn.cols()),
        M(inputs.Zn.rows()),
        var(inputs.kernel.variance()),
        se(inputs.kernel.type == KernelType::SquaredExponential),
        with_grad(gradient),
        inv_ls((-inputs.kernel.log_lengthscale.array()).exp().matrix().transpose()),
        Xs(inputs.Xn.array().rowwise() * inv_ls.array()),
        Zs(inputs.Zn.array().rowwise() * inv_ls.array()),
        Kmn(work.Kmn.matrix(M, N)),
        V(work.V.matrix(M, N)),
        R2mn(work.R2mn.matrix(!se && gradient ? M : 0, !se && gradient ? N : 0)),
        Vs(work.S.matrix(M, N)) {}

  FitcWork& ws;
  const FitcInputs& in;
  const Eigen::Index N, P, D, M;
  const double var;
  const bool se, with_grad;
  const Eigen::RowVectorXd inv_ls;
  const Eigen::MatrixXd Xs, Zs;      // inputs divided by the lengthscales
  Eigen::Map<Eigen::MatrixXd> Kmn;   // k(Z, X)
  Eigen::Map<Eigen::MatrixXd> V;     // Kmn, then L^-1 Kmn
  Eigen::Map<Eigen::MatrixXd> R2mn;  // squared scaled distances (Matern gradient only)
  Eigen::Map<Eigen::MatrixXd> Vs;    // V Lambda^-1/2 (for the SYRK of A)
  Eigen::MatrixXd R2mm, Kmm, Linv;
  Eigen::MatrixXd r;                 // (N, P) y - c (times 1/sqrt(s*) when profiled)
  Eigen::ArrayXd lam, ilam;          // (N,) FITC diagonal and its inverse
  Eigen::MatrixXd rl;                // Lambda^-1 r
  Eigen::MatrixXd Vrl;               // V Lambda^-1 r (M, P)
  Eigen::MatrixXd A;                 // I + V Lambda^-1 V^T
  double mean_grad_scale = 1.0;
};

// Kmn (and V = Kmn) by a fused distance + kernel pass column by column, Kmm.
void kernel_matrices(FitcTerms& t) {
  const Kernel& k = t.in.kernel;
  for (Eigen::Index j = 0; j < t.N; ++j) {
    auto col = t.Kmn.col(j).array();
    col = (t.Zs.col(0).array() - t.Xs(j, 0)).square();
    for (Eigen::Index d = 1; d < t.D; ++d) col += (t.Zs.col(d).array() - t.Xs(j, d)).square();
    if (!t.se && t.with_grad) t.R2mn.col(j) = t.Kmn.col(j);
    if (t.se) {
      col *= -0.5;
      exp_nonpositive(col.data(), col.data(), t.M);
      col *= t.var;
    } else {
      k.shape_inplace(t.Kmn.col(j));
      col *= t.var;
    }
    t.V.col(j) = t.Kmn.col(j);
  }
  t.R2mm = sq_dist(t.Zs, t.Zs);
  t.Kmm = t.R2mm;
  k.shape_inplace(t.Kmm);
  t.Kmm *= t.var;
}

// L = chol(Kmm + jitter) and V = L^-1 Kmn, through the explicit inverse of the M x M triangular
// factor (its forward error grows with cond(L) = sqrt(cond(Kmm)) only): the M x N product is a TRMM.
void whiten(FitcTerms& t, FitcEval& e) {
  e.L = robust_cholesky(t.Kmm, t.in.jitter0, t.var, "SparseGP K_mm", &e.jitter);
  t.Linv = lower_triangular_inverse(e.L);
  blas::trmm_left(Triangle::Lower, Op::None, t.Linv, t.V);
}

// One pass over the columns of V: lam_j = k(x_j, x_j) - |v_j|^2 + noise (floored so that a
// noise-free fit stays finite), Vs = V Lambda^-1/2 for the SYRK, and V Lambda^-1 r; then
// A = I + Vs Vs^T and LA = chol(A).
void inner_matrix(FitcTerms& t, FitcEval& e) {
  const double floor = std::max(1e-12 * t.var, 1e-300);
  t.r = t.in.Yn.rowwise() - t.in.mean_constant.transpose();
  t.lam.resize(t.N);
  t.ilam.resize(t.N);
  t.rl.resize(t.N, t.P);
  t.Vrl = Eigen::MatrixXd::Zero(t.M, t.P);
  for (Eigen::Index j = 0; j < t.N; ++j) {
    const auto v = t.V.col(j);
    t.lam[j] = std::max(std::max(t.var - v.squaredNorm(), 0.0) + t.in.noise, floor);
    t.ilam[j] = 1.0 / t.lam[j];
    t.rl.row(j) = t.r.row(j) * t.ilam[j];
    t.Vs.col(j) = std::sqrt(t.ilam[j]) * v;
    for (Eigen::Index p = 0; p < t.P; ++p) t.Vrl.col(p) += t.rl(j, p) * v;
  }
  t.A = Eigen::MatrixXd::Identity(t.M, t.M);
  blas::syrk_lower(1.0, t.Vs, 1.0, t.A);
  t.A.triangularView<Eigen::StrictlyUpper>() = t.A.transpose();
  e.LA = robust_cholesky(t.A, 0.0, 1.0, "SparseGP inner matrix");
}

// The log marginal likelihood from beta = LA^-1 V Lambda^-1 r; with profiling, at the optimal
// scale. C = s C1 for the overall scale s (variance and noise together; the jitter and the
// noise floor scale with the variance too): the LML is -quad / (2 s) - N P log(s) / 2 + ...,
// maximal at s* = quad / (N P). The gradient of the profiled LML is the gradient at s*
// (envelope theorem): the data term alpha alpha^T / s* and the model term C1^-1, i.e. the
// gradient formulas with r scaled by 1 / sqrt(s*) (alpha, beta and V Lambda^-1 r are linear in r).
void likelihood(FitcTerms& t, FitcEval& e, double* profile_log_scale) {
  const auto LAt = e.LA.triangularView<Eigen::Lower>();
  e.beta = t.Vrl;  // (M, P)
  LAt.solveInPlace(e.beta);
  const double quad = (t.r.array() * t.rl.array()).sum() - e.beta.squaredNorm();
  const double logdet = t.lam.log().sum() + 2.0 * e.LA.diagonal().array().log().sum();
  const double NP = double(t.N * t.P);
  e.lml = -0.5 * quad - 0.5 * double(t.P) * logdet - 0.5 * NP * kLog2Pi;
  if (!profile_log_scale) return;
  const double sstar = std::max(quad / NP, 1e-300);
  *profile_log_scale = std::log(sstar);
  e.lml = -0.5 * NP - 0.5 * double(t.P) * (logdet + double(t.N) * std::log(sstar)) - 0.5 * NP * kLog2Pi;
  const double f = 1.0 / std::sqrt(sstar);
  t.r *= f;
  t.Vrl *= f;
  e.beta *= f;
  t.mean_grad_scale = f;  // d LML / d c = 1^T alpha_true = 1^T alpha_scaled / sqrt(s*)
}

// The columns of the gradient with respect to Kmn, one fused pass per column j: alpha_j =
// C^-1 r = Lambda^-1 (r - V^T A^-1 V Lambda^-1 r), w_j = sum_p alpha_jp^2 - P diag(C^-1)_j with
// diag(C^-1)_j = 1/lam_j - v_j^T A^-1 v_j / lam_j^2, and (in T = A^-1 V on entry)
// dL/dKmn (before L^-T) = V alpha alpha^T - P A^-1 V Lambda^-1 - V diag(w). The same pass
// gathers the columns of V scaled by sqrt(|w|) by the sign of w into Vw (non-negative from the
// left, np of them; negative from the right, from column nn on).
void kmn_adjoint_columns(const FitcTerms& t, const Eigen::MatrixXd& Ab, const Eigen::MatrixXd& Va,
                         Eigen::Map<Eigen::MatrixXd>& T, Eigen::MatrixXd& alpha, Eigen::ArrayXd& w,
                         Eigen::Map<Eigen::MatrixXd>& Vw, Eigen::Index& np, Eigen::Index& nn) {
  np = 0;
  nn = t.N;
  for (Eigen::Index j = 0; j < t.N; ++j) {
    auto tc = T.col(j);
    const auto v = t.V.col(j);
    double a2 = 0.0;
    for (Eigen::Index p = 0; p < t.P; ++p) {
      const double a = (t.r(j, p) - v.dot(Ab.col(p))) * t.ilam[j];
      alpha(j, p) = a;
      a2 += a * a;
    }
    const double vAv = v.dot(tc);
    const double wj = a2 - double(t.P) * (t.ilam[j] - vAv * t.ilam[j] * t.ilam[j]);
    w[j] = wj;
    if (wj >= 0.0) Vw.col(np++) = std::sqrt(wj) * v;
    else Vw.col(--nn) = std::sqrt(-wj) * v;
    tc *= -double(t.P) * t.ilam[j];
    tc -= wj * v;
    for (Eigen::Index p = 0; p < t.P; ++p) tc += alpha(j, p) * Va.col(p);
  }
}

// dL/dKmm = -1/2 L^-T [ Va Va^T - P (I - A^-1) - V diag(w) V^T ] L^-1, symmetrised;
// V diag(w) V^T = Vp Vp^T - Vn Vn^T by two SYRKs (N M^2 flops together).
Eigen::MatrixXd kmm_adjoint(const FitcTerms& t, const FitcEval& e, const Eigen::MatrixXd& Ainv,
                            const Eigen::MatrixXd& Va, const Eigen::Map<Eigen::MatrixXd>& Vw, Eigen::Index np,
                            Eigen::Index nn) {
  Eigen::MatrixXd inner = Va * Va.transpose();
  inner.noalias() += double(t.P) * Ainv;
  inner.diagonal().array() -= double(t.P);
  {
    Eigen::MatrixXd VwV = Eigen::MatrixXd::Zero(t.M, t.M);
    blas::syrk_lower(1.0, Vw.leftCols(np), 0.0, VwV);
    blas::syrk_lower(-1.0, Vw.rightCols(t.N - nn), 1.0, VwV);
    VwV.triangularView<Eigen::StrictlyUpper>() = VwV.transpose();
    inner -= VwV;
  }
  blas::trsm_left(Triangle::Lower, Op::Transpose, e.L, inner);
  inner.transposeInPlace();
  blas::trsm_left(Triangle::Lower, Op::Transpose, e.L, inner);
  Eigen::MatrixXd dKmm = std::move(inner);  // L^-T inner L^-1 (symmetric)
  dKmm *= -0.5;
  dKmm = 0.5 * (dKmm + dKmm.transpose()).eval();
  return dKmm;
}

// The gradient of the negative LML: the kernel derivatives contracted with dL/dKmn and dL/dKmm
// (kernel.hpp), plus the diagonal (variance and noise) and mean terms.
void assemble_gradient(const FitcTerms& t, const FitcEval& e, FitcGradient what, const Eigen::Map<Eigen::MatrixXd>& T,
                       const Eigen::MatrixXd& dKmm, const Eigen::MatrixXd& alpha, const Eigen::ArrayXd& w,
                       Eigen::VectorXd& grad) {
  const bool grad_Z = what == FitcGradient::HyperparametersAndInducing;
  const Eigen::Index D = t.D, M = t.M;
  const int nc = t.in.mean == MeanType::Constant ? static_cast<int>(t.P) : 0;
  grad.setZero(D + 2 + nc + (grad_Z ? M * D : 0));
  Eigen::VectorXd gls = Eigen::VectorXd::Zero(D);
  double gvar = 0.0;
  Eigen::MatrixXd gZ;
  if (grad_Z) gZ = Eigen::MatrixXd::Zero(M, D);
  contract_gradient(t.in.kernel, t.Zs, t.Xs, t.R2mn, t.Kmn, T, gls, &gvar, grad_Z ? &gZ : nullptr, nullptr);
  contract_gradient(t.in.kernel, t.Zs, t.Zs, t.R2mm, t.Kmm, dKmm, gls, &gvar, grad_Z ? &gZ : nullptr,
                    grad_Z ? &gZ : nullptr);
  gvar += e.jitter * t.var * dKmm.trace();  // the jitter scales with the variance
  gvar += 0.5 * w.sum() * t.var;            // diag(Knn) = variance
  grad.head(D) = -gls;
  grad[D] = -gvar;
  grad[D + 1] = -0.5 * w.sum() * t.in.noise;
  if (nc) grad.segment(D + 2, nc) = -t.mean_grad_scale * alpha.colwise().sum().transpose();
  if (grad_Z) grad.tail(M * D) = -Eigen::Map<const Eigen::VectorXd>(gZ.data(), M * D);
}

void gradient(FitcTerms& t, const FitcEval& e, FitcGradient what, Eigen::VectorXd& grad) {
  const auto LAt = e.LA.triangularView<Eigen::Lower>();
  const Eigen::MatrixXd Ab = LAt.transpose().solve(e.beta);  // A^-1 V Lambda^-1 r (M, P)
  const Eigen::MatrixXd Ainv = inverse_from_cholesky(e.LA);
  auto T = t.ws.T.matrix(t.M, t.N);
  blas::gemm(Op::None, Op::None, 1.0, Ainv, t.V, 0.0, T);  // T = A^-1 V (M, N)
  // V alpha = V Lambda^-1 r - (V Lambda^-1 V^T) Ab = Vrl - (A - I) Ab: no pass over V
  Eigen::MatrixXd Va = t.Vrl + Ab;
  Va.noalias() -= t.A * Ab;  // (M, P)
  Eigen::MatrixXd alpha(t.N, t.P);
  Eigen::ArrayXd w(t.N);
  auto Vw = t.ws.S.matrix(t.M, t.N);  // reuses Vs's buffer (Vs is not needed any more)
  Eigen::Index np = 0, nn = t.N;
  kmn_adjoint_columns(t, Ab, Va, T, alpha, w, Vw, np, nn);
  const Eigen::MatrixXd dKmm = kmm_adjoint(t, e, Ainv, Va, Vw, np, nn);
  blas::trmm_left(Triangle::Lower, Op::Transpose, t.Linv, T);  // dL/dKmn = L^-T T
  assemble_gradient(t, e, what, T, dKmm, alpha, w, grad);
}

}  // namespace

FitcEval fitc_eval(const FitcInputs& in, FitcGradient what, Eigen::VectorXd* grad, double* profile_log_scale) {
  thread_local FitcWork ws;
  const bool with_grad = what != FitcGradient::None && grad != nullptr;
  FitcTerms t(ws, in, with_grad);
  FitcEval e;
  kernel_matrices(t);
  whiten(t, e);
  inner_matrix(t, e);
  likelihood(t, e, profile_log_scale);
  if (with_grad) gradient(t, e, what, *grad);
  return e;
}

}  // namespace bayesgrasp::gp::detail

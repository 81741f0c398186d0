#include "bayesgrasp/gp/sparse_gp.hpp"

#include "bayesgrasp/gp/blas.hpp"
#include "bayesgrasp/gp/vector_exp.hpp"
#include "bayesgrasp/gp/workspace.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include <cmath>
#include <stdexcept>

namespace bayesgrasp::gp {

namespace {
constexpr double kLog2Pi = 1.8378770664093453;

// One FITC evaluation. Notation: Kmn = k(Z, X) (M x N), L = chol(Kmm + jitter), V = L^-1 Kmn,
// lam = diag(Knn - V^T V) + noise, A = I + V diag(1/lam) V^T = L^-1 B L^-T, LA = chol(A).
// The O(N M^2) work, all BLAS level 3 (blas.hpp): V (TRMM with the explicit M x M triangular
// inverse, N M^2), A (SYRK, N M^2), A^-1 V (GEMM, 2 N M^2), L^-T (dL/dV) (TRMM, N M^2),
// V diag(w) V^T (two SYRKs over the columns of either sign of w, N M^2): 6 N M^2 flops;
// nothing N x N. The whitened form (A >= I) keeps lam and the
// gradient accurate when Kmm is ill-conditioned (a Kmm^-1 / B^-1 form with 6 N M^2 flops was
// 25% faster but its noisy gradients stalled L-BFGS on the benchmark data).
struct FitcEval {
  Eigen::MatrixXd L, LA;
  Eigen::MatrixXd beta;  // (M, P) LA^-1 V diag(1/lam) (y - c)
  double lml = 0.0;
  double jitter = 0.0;
};

// Per-thread workspace: the M x N matrices are reused between evaluations (workspace.hpp).
struct FitcWork {
  detail::Workspace Kmn, R2mn, V, S, T;
};

FitcEval fitc_eval(const Eigen::MatrixXd& Xn, const Eigen::MatrixXd& Yn, const Eigen::MatrixXd& Zn, const Kernel& k,
                   double noise, const Eigen::VectorXd& c, double jitter0, Eigen::VectorXd* grad,
                   bool constant_mean, bool grad_Z, double* profile_log_scale = nullptr) {
  const Eigen::Index N = Xn.rows(), P = Yn.cols(), D = Xn.cols(), M = Zn.rows();
  const double var = k.variance();
  const bool se = k.type == KernelType::SquaredExponential;
  const Eigen::RowVectorXd inv_ls = (-k.log_lengthscale.array()).exp().matrix().transpose();
  const Eigen::MatrixXd Xs = Xn.array().rowwise() * inv_ls.array();
  const Eigen::MatrixXd Zs = Zn.array().rowwise() * inv_ls.array();

  thread_local FitcWork ws;
  auto Kmn = ws.Kmn.matrix(M, N);
  auto V = ws.V.matrix(M, N);  // (M, N), L^-1 Kmn below; filled with Kmn in the same pass
  auto R2mn = ws.R2mn.matrix(!se && grad ? M : 0, !se && grad ? N : 0);
  for (Eigen::Index j = 0; j < N; ++j) {  // fused distance + kernel, column by column
    auto col = Kmn.col(j).array();
    col = (Zs.col(0).array() - Xs(j, 0)).square();
    for (Eigen::Index d = 1; d < D; ++d) col += (Zs.col(d).array() - Xs(j, d)).square();
    if (!se && grad) R2mn.col(j) = Kmn.col(j);
    if (se) {
      col *= -0.5;
      detail::exp_nonpositive(col.data(), col.data(), M);
      col *= var;
    } else {
      k.shape_inplace(Kmn.col(j));
      col *= var;
    }
    V.col(j) = Kmn.col(j);
  }
  Eigen::MatrixXd R2mm = detail::sq_dist(Zs, Zs);
  Eigen::MatrixXd Kmm = R2mm;
  k.shape_inplace(Kmm);
  Kmm *= var;

  FitcEval e;
  e.L = robust_cholesky(Kmm, jitter0, var, "SparseGP K_mm", &e.jitter);
  const Eigen::MatrixXd& Lc = e.L;
  // Explicit inverse of the M x M triangular factor (its forward error grows with
  // cond(L) = sqrt(cond(Kmm)) only): the M x N products with it below are TRMMs.
  Eigen::MatrixXd Linv = Eigen::MatrixXd::Identity(M, M);
  blas::trsm_left(true, false, Lc, Linv);
  blas::trmm_left(true, false, Linv, V);  // V = L^-1 Kmn
  // One pass over the columns of V: lam_j = k(x_j, x_j) - |v_j|^2 + noise (floored so that a
  // noise-free fit stays finite), Vs = V Lambda^-1/2 for the SYRK, and V Lambda^-1 r.
  const double floor = std::max(1e-12 * var, 1e-300);
  Eigen::MatrixXd r = Yn.rowwise() - c.transpose();  // (N, P)
  Eigen::ArrayXd lam(N), ilam(N);
  Eigen::MatrixXd rl(N, P);                                 // Lambda^-1 r
  auto Vs = ws.S.matrix(M, N);
  Eigen::MatrixXd Vrl = Eigen::MatrixXd::Zero(M, P);        // V Lambda^-1 r
  for (Eigen::Index j = 0; j < N; ++j) {
    const auto v = V.col(j);
    lam[j] = std::max(std::max(var - v.squaredNorm(), 0.0) + noise, floor);
    ilam[j] = 1.0 / lam[j];
    rl.row(j) = r.row(j) * ilam[j];
    Vs.col(j) = std::sqrt(ilam[j]) * v;
    for (Eigen::Index p = 0; p < P; ++p) Vrl.col(p) += rl(j, p) * v;
  }
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(M, M);
  blas::syrk_lower(1.0, Vs, 1.0, A);
  A.triangularView<Eigen::StrictlyUpper>() = A.transpose();
  e.LA = robust_cholesky(A, 0.0, 1.0, "SparseGP inner matrix");
  const Eigen::MatrixXd& LAc = e.LA;
  const auto LAt = LAc.triangularView<Eigen::Lower>();

  e.beta = Vrl;                                                    // (M, P)
  LAt.solveInPlace(e.beta);
  const double quad = (r.array() * rl.array()).sum() - e.beta.squaredNorm();
  const double logdet = lam.log().sum() + 2.0 * e.LA.diagonal().array().log().sum();
  e.lml = -0.5 * quad - 0.5 * double(P) * logdet - 0.5 * double(N * P) * kLog2Pi;
  double mean_grad_scale = 1.0;
  if (profile_log_scale) {
    // C = s C1 for the overall scale s (variance and noise together; the jitter and the
    // noise floor scale with the variance too): the LML is -quad / (2 s) - N P log(s) / 2 + ...,
    // maximal at s* = quad / (N P). The gradient of the profiled LML is the gradient at s*
    // (envelope theorem): the data term alpha alpha^T / s* and the model term C1^-1, i.e. the
    // formulas below with r scaled by 1 / sqrt(s*) (alpha, beta and V Lambda^-1 r are linear in r).
    const double NP = double(N * P);
    const double sstar = std::max(quad / NP, 1e-300);
    *profile_log_scale = std::log(sstar);
    e.lml = -0.5 * NP - 0.5 * double(P) * (logdet + double(N) * std::log(sstar)) - 0.5 * NP * kLog2Pi;
    const double f = 1.0 / std::sqrt(sstar);
    r *= f;
    Vrl *= f;
    e.beta *= f;
    mean_grad_scale = f;  // d LML / d c = 1^T alpha_true = 1^T alpha_scaled / sqrt(s*)
  }
  if (!grad) return e;

  // alpha = C^-1 r = Lambda^-1 (r - V^T A^-1 V Lambda^-1 r)
  const Eigen::MatrixXd Ab = LAt.transpose().solve(e.beta);        // A^-1 V Lambda^-1 r (M, P)
  Eigen::MatrixXd alpha(N, P);  // filled column by column in the pass below
  // T = A^-1 V (explicit A^-1: one GEMM)
  Eigen::MatrixXd Ainv = Eigen::MatrixXd::Identity(M, M);
  blas::trsm_left(true, false, LAc, Ainv);
  blas::trsm_left(true, true, LAc, Ainv);
  auto T = ws.T.matrix(M, N);
  blas::gemm(false, false, 1.0, Ainv, V, 0.0, T);  // (M, N)
  // diag(C^-1)_i = 1/lam_i - v_i^T A^-1 v_i / lam_i^2 ; w_i = sum_p alpha_ip^2 - P diag(C^-1)_i
  // V alpha = V Lambda^-1 r - (V Lambda^-1 V^T) Ab = Vrl - (A - I) Ab: no pass over V
  Eigen::MatrixXd Va = Vrl + Ab;
  Va.noalias() -= A * Ab;  // (M, P)
  // One fused pass per column j: w_j from v_j^T A^-1 v_j, then
  // dL/dKmn (before L^-T) = V alpha alpha^T - P A^-1 V Lambda^-1 - V diag(w), built in T.
  // The same pass gathers the columns of V scaled by sqrt(|w|) by the sign of w, for
  // V diag(w) V^T = Vp Vp^T - Vn Vn^T below (two SYRKs, N M^2 flops together).
  Eigen::ArrayXd w(N);
  auto Vw = ws.S.matrix(M, N);
  Eigen::Index np = 0, nn = N;
  for (Eigen::Index j = 0; j < N; ++j) {
    auto t = T.col(j);
    const auto v = V.col(j);
    double a2 = 0.0;
    for (Eigen::Index p = 0; p < P; ++p) {
      const double a = (r(j, p) - v.dot(Ab.col(p))) * ilam[j];
      alpha(j, p) = a;
      a2 += a * a;
    }
    const double vAv = v.dot(t);
    const double wj = a2 - double(P) * (ilam[j] - vAv * ilam[j] * ilam[j]);
    w[j] = wj;
    if (wj >= 0.0) Vw.col(np++) = std::sqrt(wj) * v;
    else Vw.col(--nn) = std::sqrt(-wj) * v;
    t *= -double(P) * ilam[j];
    t -= wj * v;
    for (Eigen::Index p = 0; p < P; ++p) t += alpha(j, p) * Va.col(p);
  }
  // dL/dKmm = -1/2 L^-T [ Va Va^T - P (I - A^-1) - V diag(w) V^T ] L^-1
  Eigen::MatrixXd inner = Va * Va.transpose();
  inner.noalias() += double(P) * Ainv;
  inner.diagonal().array() -= double(P);
  {
    Eigen::MatrixXd VwV = Eigen::MatrixXd::Zero(M, M);
    blas::syrk_lower(1.0, Vw.leftCols(np), 0.0, VwV);
    blas::syrk_lower(-1.0, Vw.rightCols(N - nn), 1.0, VwV);
    VwV.triangularView<Eigen::StrictlyUpper>() = VwV.transpose();
    inner -= VwV;
  }
  blas::trmm_left(true, true, Linv, T);  // dL/dKmn = L^-T T
  blas::trsm_left(true, true, Lc, inner);
  inner.transposeInPlace();
  blas::trsm_left(true, true, Lc, inner);
  Eigen::MatrixXd dKmm = std::move(inner);  // L^-T inner L^-1 (symmetric)
  dKmm *= -0.5;
  dKmm = 0.5 * (dKmm + dKmm.transpose()).eval();

  const int nc = constant_mean ? static_cast<int>(P) : 0;
  grad->setZero(D + 2 + nc + (grad_Z ? M * D : 0));
  Eigen::VectorXd gls = Eigen::VectorXd::Zero(D);
  double gvar = 0.0;
  Eigen::MatrixXd gZ;
  if (grad_Z) gZ = Eigen::MatrixXd::Zero(M, D);
  detail::contract_gradient(k, Zs, Xs, R2mn, Kmn, T, gls, &gvar, grad_Z ? &gZ : nullptr, nullptr);
  detail::contract_gradient(k, Zs, Zs, R2mm, Kmm, dKmm, gls, &gvar, grad_Z ? &gZ : nullptr,
                            grad_Z ? &gZ : nullptr);
  gvar += e.jitter * var * dKmm.trace();  // the jitter scales with the variance
  gvar += 0.5 * w.sum() * var;            // diag(Knn) = variance
  grad->head(D) = -gls;
  (*grad)[D] = -gvar;
  (*grad)[D + 1] = -0.5 * w.sum() * noise;
  if (nc) grad->segment(D + 2, nc) = -mean_grad_scale * alpha.colwise().sum().transpose();
  if (grad_Z) grad->tail(M * D) = -Eigen::Map<const Eigen::VectorXd>(gZ.data(), M * D);
  return e;
}
}  // namespace

SparseGP::SparseGP(GPOptions options) : GaussianProcess(std::move(options)) {}

Eigen::VectorXd SparseGP::parameters() const {
  Eigen::VectorXd base = GaussianProcess::parameters();
  if (!opt_.optimize_inducing) return base;
  Eigen::VectorXd t(base.size() + Zn_.size());
  t << base, Eigen::Map<const Eigen::VectorXd>(Zn_.data(), Zn_.size());
  return t;
}

double SparseGP::objective(const Eigen::VectorXd& theta, Eigen::VectorXd& grad) const {
  if (Xn_.size() == 0) throw std::logic_error("objective: no training data; call fit() first");
  Kernel k;
  double noise;
  Eigen::VectorXd c;
  Eigen::MatrixXd Z = Zn_;
  unpack(theta, k, noise, c, &Z);
  const bool gz = theta.size() > dim_ + 2 + (opt_.mean == MeanType::Constant ? outputs_ : 0);
  if (gz && Z.rows() != Zn_.rows()) throw std::invalid_argument("theta: inducing block has the wrong size");
  const FitcEval e = fitc_eval(Xn_, Yn_, Z, k, noise, c, opt_.jitter, &grad, opt_.mean == MeanType::Constant, gz);
  return -e.lml;
}

double SparseGP::profiled_objective(const Eigen::VectorXd& theta_p, Eigen::VectorXd& grad, double* log_scale) const {
  if (Xn_.size() == 0) throw std::logic_error("objective: no training data; call fit() first");
  const int D = dim_;
  const int nc = opt_.mean == MeanType::Constant ? outputs_ : 0;
  if (theta_p.size() != D + 1 + nc) throw std::invalid_argument("theta_p: expected D + 1 (+ P) entries");
  Eigen::VectorXd theta(D + 2 + nc);
  theta << theta_p.head(D), 0.0, theta_p.tail(1 + nc);  // log variance 0: the scale is profiled
  Kernel k;
  double noise;
  Eigen::VectorXd c;
  unpack(theta, k, noise, c, nullptr);
  Eigen::VectorXd g;
  double ls = 0.0;
  const FitcEval e = fitc_eval(Xn_, Yn_, Zn_, k, noise, c, opt_.jitter, &g, nc > 0, false, &ls);
  grad.resize(theta_p.size());
  grad << g.head(D), g.tail(1 + nc);  // drop d/dlog variance (zero at the profiled scale)
  if (log_scale) *log_scale = ls;
  return -e.lml;
}

Eigen::MatrixXd SparseGP::inducing_inputs() const {
  return (Zn_.array().rowwise() * x_scale_.transpose().array()).rowwise() + x_mean_.transpose().array();
}

void SparseGP::fit(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) {
  set_training_data(X, Y);
  if (opt_.inducing.size() > 0) {
    Zn_ = (opt_.inducing.rowwise() - x_mean_.transpose()).array().rowwise() / x_scale_.transpose().array();
  } else {
    const int M = static_cast<int>(std::min<Eigen::Index>(opt_.n_inducing, Xn_.rows()));
    Zn_ = kmeans_pp(Xn_, M, opt_.seed, opt_.kmeans_iter);
  }
  if (opt_.optimize && opt_.max_iter > 0) {
    const Eigen::VectorXd best = optimise(opt_.optimize_inducing ? static_cast<int>(Zn_.size()) : 0);
    if (opt_.optimize_inducing) {
      Kernel k;
      double nz;
      Eigen::VectorXd c;
      Eigen::MatrixXd Z = Zn_;
      unpack(best, k, nz, c, &Z);
      Zn_ = Z;
    }
  }
  build_cache();
  fitted_ = true;
}

void SparseGP::build_cache() {
  const FitcEval e = fitc_eval(Xn_, Yn_, Zn_, kernel_, noise_, mean_c_, opt_.jitter, nullptr, false, false);
  lml_ = e.lml;
  info_.log_marginal_likelihood = e.lml;
  info_.jitter_used = e.jitter;
  const double var = kernel_.variance();
  const Eigen::Index M = Zn_.rows();
  cache_.type = kernel_.type;
  cache_.inv_ls = (kernel_.log_lengthscale.array().exp() * x_scale_.array()).inverse().matrix();
  cache_.basis = inducing_inputs().array().rowwise() * cache_.inv_ls.transpose().array();
  // mean weights: L^-T LA^-T beta
  Eigen::MatrixXd wts = e.LA.triangularView<Eigen::Lower>().transpose().solve(e.beta);
  e.L.triangularView<Eigen::Lower>().transpose().solveInPlace(wts);
  cache_.alpha = (wts * var).array().rowwise() * y_scale_.transpose().array();
  cache_.offset = (y_mean_ + y_scale_.cwiseProduct(mean_c_)).transpose();
  // var_f = var - var^2 f^T L^-T (I - A^-1) L^-1 f;  I - A^-1 = Q diag(1 - 1/s) Q^T.
  Eigen::MatrixXd A = e.LA * e.LA.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A);
  if (es.info() != Eigen::Success) throw std::runtime_error("SparseGP: eigen-decomposition failed");
  const Eigen::ArrayXd d = (1.0 - es.eigenvalues().array().inverse()).max(0.0).sqrt() * std::sqrt(var);
  Eigen::MatrixXd G = d.matrix().asDiagonal() * es.eigenvectors().transpose();  // (M, M)
  // G L^-1: solve from the right: (L^-T G^T)^T
  Eigen::MatrixXd Gt = G.transpose();
  e.L.triangularView<Eigen::Lower>().transpose().solveInPlace(Gt);
  // Householder QR: G = Q R  =>  |G f| = |R f| with R upper triangular (half the flops per
  // input in prediction); backward stable and needs no jitter when R is rank deficient.
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(Gt.transpose());
  cache_.G = qr.matrixQR().triangularView<Eigen::Upper>();
  cache_.G_shape = 2;
  pack_factor();
  cache_.var_f0 = (y_scale_.array().square() * var).matrix().transpose();
  cache_.noise = (y_scale_.array().square() * noise_).matrix().transpose();
  (void)M;
}

}  // namespace bayesgrasp::gp

#include "bayesgrasp/gp/gaussian_process.hpp"

#include "bayesgrasp/gp/vector_exp.hpp"

#include <Eigen/Cholesky>
#include <LBFGSB.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace bayesgrasp::gp {

namespace {
using namespace detail;  // vector_exp.hpp: vd, kW, vload, vstore, vbroadcast, exp_nonpositive

constexpr double kLog2Pi = 1.8378770664093453;
constexpr int kBlock = 128;          // inputs per prediction block
constexpr int kParallelMin = 2048;   // batches at least this large use opt.threads

// F (M x n): kernel shape between the cache basis and n raw inputs (rows i0.. of X).
template <class Cache>
void shape_block(const Cache& c, const Eigen::MatrixXd& X, Eigen::Index i0, Eigen::Index n,
                 Eigen::MatrixXd& F) {
  const Eigen::Index D = c.basis.cols();
  F.resize(c.basis.rows(), n);
  for (Eigen::Index j = 0; j < n; ++j) {
    auto f = F.col(j).array();
    f = (c.basis.col(0).array() - X(i0 + j, 0) * c.inv_ls[0]).square();
    for (Eigen::Index d = 1; d < D; ++d) f += (c.basis.col(d).array() - X(i0 + j, d) * c.inv_ls[d]).square();
  }
  if (c.type == KernelType::SquaredExponential) {
    F.array() = (-0.5 * F.array()).exp();
  } else {
    for (Eigen::Index j = 0; j < n; ++j) {
      auto f = F.col(j).array();
      const Eigen::ArrayXd s = (5.0 * f).sqrt();
      f = (1.0 + s + s.square() * (1.0 / 3.0)) * (-s).exp();
    }
  }
}

// H = (variance factor) F for the cache's factor shape.
template <class Cache>
void apply_factor(const Cache& c, const Eigen::MatrixXd& F, Eigen::MatrixXd& H) {
  switch (c.G_shape) {
    case 1: H.noalias() = c.G.template triangularView<Eigen::Lower>() * F; break;
    case 2: H.noalias() = c.G.template triangularView<Eigen::Upper>() * F; break;
    case 3: H = c.G.template triangularView<Eigen::Lower>().solve(F); break;
    default: H.noalias() = c.G * F;
  }
}

// ---- fused mean + variance kernel (upper-triangular factor, packed) ------------------------
// Inputs are processed in groups of kGroup: their kernel vectors F (M x kGroup, row k holds
// f_k for the group's inputs, contiguous) are built in a small buffer, then the mean and
// q_j = |G f_j|^2 are accumulated in registers: for a tile of kMR rows of G, H(tile, group) =
// G(tile, k >= i0) F(k >= i0, group) and q += H^2, without storing H. That is M^2 flops per
// input (multiply-adds over the upper triangle), the same arithmetic as Eigen's TRMM but with
// the reduction fused and no (n x M) matrices beyond the L1/L2-sized buffer.
#if defined(__AVX512F__)
constexpr int kNV = 3, kMR = 8;   // 24 accumulators of 32 zmm registers (3x8 measured
                                  // fastest of 4x6, 2x8, 3x7, 3x9, 2x12 on Zen 4)
#elif defined(__AVX__)
constexpr int kNV = 3, kMR = 4;   // 12 of 16 ymm
#else
constexpr int kNV = 3, kMR = 4;   // 12 of 16 xmm
#endif
constexpr int kGroup = kW * kNV;

// Packed layout of an upper-triangular M x M factor G: tile t covers rows i0 = t*kMR ..
// i0+kMR-1 (rows >= M are zero padding) and columns k = i0 .. M-1; entry (ii, k) sits at
// offset(t) + (k - i0) * kMR + ii. offset(t) = kMR * sum_{s<t} (M - s*kMR).
std::vector<double> pack_upper(const Eigen::MatrixXd& G) {
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
template <class Cache>
void shape_group(const Cache& c, const Eigen::MatrixXd& X, Eigen::Index i0, int n, double* F) {
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
template <class Cache>
bool mean_group_se(const Cache& c, const Eigen::MatrixXd& X, Eigen::Index i0, int n, const double* alpha,
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

int threads_for(Eigen::Index n, int threads) { return n >= kParallelMin ? std::max(1, threads) : 1; }

}  // namespace

MeanType mean_type_from_string(const std::string& name) {
  if (name == "zero") return MeanType::Zero;
  if (name == "constant") return MeanType::Constant;
  throw std::invalid_argument("mean: expected 'zero' or 'constant', got '" + name + "'");
}
std::string mean_type_name(MeanType type) { return type == MeanType::Zero ? "zero" : "constant"; }

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

Eigen::MatrixXd kmeans_pp(const Eigen::MatrixXd& X, int k, std::uint64_t seed, int iters) {
  const Eigen::Index N = X.rows(), D = X.cols();
  if (N == 0 || k <= 0) throw std::invalid_argument("kmeans_pp: need points and k >= 1");
  std::mt19937_64 rng(seed);
  std::vector<Eigen::Index> chosen;
  chosen.push_back(std::uniform_int_distribution<Eigen::Index>(0, N - 1)(rng));
  Eigen::ArrayXd d2 = (X.rowwise() - X.row(chosen[0])).rowwise().squaredNorm().array();
  std::uniform_real_distribution<double> U(0.0, 1.0);
  while (static_cast<int>(chosen.size()) < k) {
    const double total = d2.sum();
    if (!(total > 0.0)) break;  // fewer distinct points than k
    double u = U(rng) * total, acc = 0.0;
    Eigen::Index pick = -1;
    for (Eigen::Index i = 0; i < N; ++i) {
      acc += d2[i];
      if (d2[i] > 0.0) pick = i;
      if (acc >= u && d2[i] > 0.0) break;
    }
    chosen.push_back(pick);
    d2 = d2.min((X.rowwise() - X.row(pick)).rowwise().squaredNorm().array());
  }
  const Eigen::Index K = static_cast<Eigen::Index>(chosen.size());
  Eigen::MatrixXd C(K, D);
  for (Eigen::Index c = 0; c < K; ++c) C.row(c) = X.row(chosen[c]);
  // Lloyd iterations (empty clusters keep their centre).
  Eigen::VectorXi assign(N);
  for (int it = 0; it < iters; ++it) {
    for (Eigen::Index i = 0; i < N; ++i) {
      Eigen::Index best;
      (C.rowwise() - X.row(i)).rowwise().squaredNorm().minCoeff(&best);
      assign[i] = static_cast<int>(best);
    }
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(K, D);
    Eigen::VectorXd cnt = Eigen::VectorXd::Zero(K);
    for (Eigen::Index i = 0; i < N; ++i) {
      S.row(assign[i]) += X.row(i);
      cnt[assign[i]] += 1.0;
    }
    for (Eigen::Index c = 0; c < K; ++c)
      if (cnt[c] > 0) C.row(c) = S.row(c) / cnt[c];
  }
  return C;
}

// ------------------------------------------------------------------------------------------
GaussianProcess::GaussianProcess(GPOptions o) : opt_(std::move(o)) {
  if (opt_.lengthscale.size() > 0 &&
      (!(opt_.lengthscale.array() > 0.0).all() || !opt_.lengthscale.allFinite()))
    throw std::invalid_argument("lengthscale: must be positive and finite");
  if (!(opt_.variance > 0.0) || !std::isfinite(opt_.variance))
    throw std::invalid_argument("variance: must be positive and finite");
  if (!(opt_.noise >= 0.0) || !std::isfinite(opt_.noise))
    throw std::invalid_argument("noise: must be non-negative and finite");
  if (opt_.max_iter < 0) throw std::invalid_argument("max_iter: must be >= 0");
  if (opt_.n_inducing < 1) throw std::invalid_argument("n_inducing: must be >= 1");
  if (!(opt_.jitter >= 0.0) || !std::isfinite(opt_.jitter)) throw std::invalid_argument("jitter: must be >= 0");
  if (opt_.kmeans_iter < 0) throw std::invalid_argument("kmeans_iter: must be >= 0");
  if (opt_.threads < 1) opt_.threads = 1;
  if (opt_.mean_constant.size() > 0 && !opt_.mean_constant.allFinite())
    throw std::invalid_argument("mean_constant: contains NaN or infinity");
  if (opt_.inducing.size() > 0 && !opt_.inducing.allFinite())
    throw std::invalid_argument("inducing: contains NaN or infinity");
  noise_ = opt_.noise;
}

void GaussianProcess::check_fitted(const char* what) const {
  if (!fitted_) throw std::logic_error(std::string(what) + ": the model is not fitted; call fit() first");
}

void GaussianProcess::check_inputs(const Eigen::MatrixXd& X, const char* name) const {
  if (X.cols() != dim_)
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(dim_) + " columns, got " +
                                std::to_string(X.cols()));
  if (!X.allFinite()) throw std::invalid_argument(std::string(name) + ": contains NaN or infinity");
}

void GaussianProcess::set_training_data(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) {
  if (X.rows() == 0 || X.cols() == 0) throw std::invalid_argument("X: is empty");
  if (Y.rows() != X.rows())
    throw std::invalid_argument("y: has " + std::to_string(Y.rows()) + " rows but X has " + std::to_string(X.rows()));
  if (Y.cols() == 0) throw std::invalid_argument("y: has no outputs");
  if (!X.allFinite()) throw std::invalid_argument("X: contains NaN or infinity");
  if (!Y.allFinite()) throw std::invalid_argument("y: contains NaN or infinity");
  const Eigen::Index N = X.rows(), D = X.cols(), P = Y.cols();
  if (opt_.lengthscale.size() != 0 && opt_.lengthscale.size() != 1 && opt_.lengthscale.size() != D)
    throw std::invalid_argument("lengthscale: expected 1 or " + std::to_string(D) + " values, got " +
                                std::to_string(opt_.lengthscale.size()));
  if (opt_.inducing.size() > 0 && opt_.inducing.cols() != D)
    throw std::invalid_argument("inducing: expected " + std::to_string(D) + " columns");
  dim_ = static_cast<int>(D);
  outputs_ = static_cast<int>(P);
  X_ = X;
  Y_ = Y;
  auto standardise = [N](const Eigen::MatrixXd& A, bool on, Eigen::VectorXd& m, Eigen::VectorXd& s) {
    m = Eigen::VectorXd::Zero(A.cols());
    s = Eigen::VectorXd::Ones(A.cols());
    if (!on) return;
    m = A.colwise().mean().transpose();
    for (Eigen::Index j = 0; j < A.cols(); ++j) {
      const double sd = N > 1 ? std::sqrt((A.col(j).array() - m[j]).square().sum() / double(N)) : 0.0;
      // A constant column keeps scale 1 (relative to its magnitude, so huge offsets stay exact).
      s[j] = (sd > 1e-300 && sd > 1e-12 * std::abs(m[j])) ? sd : 1.0;
    }
  };
  standardise(X, opt_.normalize_x, x_mean_, x_scale_);
  standardise(Y, opt_.normalize_y, y_mean_, y_scale_);
  Xn_ = (X.rowwise() - x_mean_.transpose()).array().rowwise() / x_scale_.transpose().array();
  Yn_ = (Y.rowwise() - y_mean_.transpose()).array().rowwise() / y_scale_.transpose().array();
  Eigen::VectorXd ls = Eigen::VectorXd::Ones(D);
  if (opt_.lengthscale.size() == 1) ls.setConstant(opt_.lengthscale[0]);
  if (opt_.lengthscale.size() == D) ls = opt_.lengthscale;
  kernel_ = Kernel(opt_.kernel, ls, opt_.variance);
  noise_ = opt_.noise;
  mean_c_ = Eigen::VectorXd::Zero(P);
  if (opt_.mean == MeanType::Constant && !opt_.normalize_y) mean_c_ = Yn_.colwise().mean().transpose();
  if (opt_.mean == MeanType::Constant && opt_.mean_constant.size() > 0) {
    if (opt_.mean_constant.size() != P)
      throw std::invalid_argument("mean_constant: expected " + std::to_string(P) + " values");
    mean_c_ = opt_.mean_constant;
  }
  fitted_ = false;
}

Eigen::VectorXd GaussianProcess::parameters() const {
  const int D = kernel_.dim(), P = outputs_;
  const int nc = opt_.mean == MeanType::Constant ? P : 0;
  Eigen::VectorXd t(D + 2 + nc);
  t.head(D) = kernel_.log_lengthscale;
  t[D] = kernel_.log_variance;
  t[D + 1] = std::log(std::max(noise_, 1e-12));
  if (nc) t.segment(D + 2, nc) = mean_c_;
  return t;
}

void GaussianProcess::unpack(const Eigen::VectorXd& theta, Kernel& k, double& noise, Eigen::VectorXd& c,
                             Eigen::MatrixXd* Z) const {
  const int D = dim_, P = outputs_;
  const int nc = opt_.mean == MeanType::Constant ? P : 0;
  const Eigen::Index base = D + 2 + nc;
  if (theta.size() < base) throw std::invalid_argument("theta: too short");
  if (!theta.allFinite()) throw std::invalid_argument("theta: contains NaN or infinity");
  k.type = opt_.kernel;
  k.log_lengthscale = theta.head(D);
  k.log_variance = theta[D];
  noise = std::exp(theta[D + 1]);
  c = nc ? Eigen::VectorXd(theta.segment(D + 2, nc)) : Eigen::VectorXd::Zero(P);
  if (Z && theta.size() > base) {
    const Eigen::Index M = (theta.size() - base) / D;
    if (M * D != theta.size() - base) throw std::invalid_argument("theta: bad length");
    *Z = Eigen::Map<const Eigen::MatrixXd>(theta.data() + base, M, D);
  }
}

Eigen::VectorXd GaussianProcess::optimise(int n_extra) {
  Eigen::VectorXd x = parameters();
  const int D = dim_, P = outputs_;
  const Eigen::Index n = x.size();
  // Box bounds relative to the data's scales keep L-BFGS-B away from degenerate corners.
  Eigen::VectorXd lb = Eigen::VectorXd::Constant(n, -1e10), ub = Eigen::VectorXd::Constant(n, 1e10);
  double yv = 0.0;
  for (int p = 0; p < P; ++p) yv += (Yn_.col(p).array() - Yn_.col(p).mean()).square().mean();
  yv = yv / P;
  if (!(yv > 1e-300)) yv = std::max(1e-300, Yn_.array().square().mean());
  if (!(yv > 1e-300)) yv = 1.0;
  for (int d = 0; d < D; ++d) {
    const Eigen::ArrayXd c = Xn_.col(d).array();
    double range = c.maxCoeff() - c.minCoeff();
    if (!(range > 0.0)) range = 1.0;
    lb[d] = std::log(1e-3 * range);
    ub[d] = std::log(1e4 * range);
  }
  lb[D] = std::log(1e-6 * yv);
  ub[D] = std::log(1e6 * yv);
  lb[D + 1] = std::log(1e-9 * yv);
  ub[D + 1] = std::log(1e2 * yv);
  x = x.cwiseMax(lb).cwiseMin(ub);
  // Profiled scale (GPOptions::profile_scale): drop the log variance; the log noise entry
  // becomes log(noise / variance), bounded by the box above.
  const bool prof = opt_.profile_scale && n_extra == 0 && supports_profile();
  const Eigen::VectorXd lb_full = lb, ub_full = ub;
  if (prof) {
    auto drop = [&](const Eigen::VectorXd& v, double ratio_entry) {
      Eigen::VectorXd out(v.size() - 1);
      out << v.head(D), ratio_entry, v.tail(v.size() - D - 2);
      return out;
    };
    x = drop(x, x[D + 1] - x[D]);
    lb = drop(lb, lb_full[D + 1] - ub_full[D]);
    ub = drop(ub, ub_full[D + 1] - lb_full[D]);
  }

  LBFGSpp::LBFGSBParam<double> param;
  param.m = 10;
  param.epsilon = 1e-5;
  param.epsilon_rel = 0.0;
  param.past = 1;
  param.delta = 2.2e-9;  // scipy's L-BFGS-B default factr = 1e7
  param.max_iterations = opt_.max_iter;
  param.max_linesearch = 30;
  LBFGSpp::LBFGSBSolver<double> solver(param);

  struct Fn {
    const GaussianProcess* self;
    bool prof = false;
    int evals = 0;
    double best_f = std::numeric_limits<double>::infinity();
    Eigen::VectorXd best_x;
    double best_log_scale = 0.0;
    std::string last_error;
    double operator()(const Eigen::VectorXd& t, Eigen::VectorXd& g) {
      ++evals;
      double f, ls = 0.0;
      try {
        f = prof ? self->profiled_objective(t, g, &ls) : self->objective(t, g);
      } catch (const std::runtime_error& e) {
        last_error = e.what();
        g.setZero();
        return std::isfinite(best_f) ? std::abs(best_f) * 10.0 + 1e10 : 1e300;
      }
      if (!std::isfinite(f) || !g.allFinite()) {
        g.setZero();
        return std::isfinite(best_f) ? std::abs(best_f) * 10.0 + 1e10 : 1e300;
      }
      if (f < best_f) {
        best_f = f;
        best_x = t;
        best_log_scale = ls;
      }
      return f;
    }
  } fn{this, prof, 0, std::numeric_limits<double>::infinity(), Eigen::VectorXd(), 0.0, std::string()};
  double fx = 0.0;
  info_ = FitInfo{};
  try {
    info_.iterations = solver.minimize(fn, x, fx, lb, ub);
    info_.message = "converged";
  } catch (const std::exception& e) {
    info_.message = std::string("stopped: ") + e.what();
  }
  info_.evaluations = fn.evals;
  if (fn.best_x.size() == 0)
    throw std::runtime_error("fit: the log marginal likelihood could not be evaluated at the initial "
                             "hyper-parameters (" + fn.last_error + ")");
  if (prof) {  // back to [log lengthscales, log variance, log noise, ...]
    const Eigen::VectorXd t = fn.best_x;
    fn.best_x.resize(t.size() + 1);
    fn.best_x << t.head(D), fn.best_log_scale, t[D] + fn.best_log_scale, t.tail(t.size() - D - 1);
  }
  Eigen::VectorXd c;
  unpack(fn.best_x, kernel_, noise_, c, nullptr);
  mean_c_ = c;
  return fn.best_x;
}

double GaussianProcess::profiled_objective(const Eigen::VectorXd&, Eigen::VectorXd&, double*) const {
  throw std::logic_error("profiled_objective: not supported by this model");
}

void GaussianProcess::pack_factor() {
  cache_.G_packed.clear();
  if (cache_.G_shape == 2 && cache_.G.rows() == cache_.G.cols() && cache_.G.rows() == cache_.basis.rows())
    cache_.G_packed = pack_upper(cache_.G);
}

// ---- prediction on the cache -------------------------------------------------------------
Eigen::MatrixXd GaussianProcess::predict_mean(const Eigen::MatrixXd& X) const {
  check_fitted("predict_mean");
  check_inputs(X, "X");
  const Eigen::Index N = X.rows(), P = outputs_;
  Eigen::MatrixXd out(N, P);
  // Groups of kGroup inputs: kernel vectors in a small buffer (own vectorised exp), then the
  // weighted sums in registers, as in the fused mean + variance path below.
  const Eigen::Index M = cache_.basis.rows();
  const Eigen::Index ngroups = (N + kGroup - 1) / kGroup;
#pragma omp parallel num_threads(threads_for(N, opt_.threads))
  {
    std::vector<double> F(static_cast<std::size_t>(M) * kGroup);
    alignas(64) double m[kGroup];
#pragma omp for schedule(static)
    for (Eigen::Index g = 0; g < ngroups; ++g) {
      const Eigen::Index i0 = g * kGroup;
      const int n = static_cast<int>(std::min<Eigen::Index>(kGroup, N - i0));
      if (P == 1 && mean_group_se(cache_, X, i0, n, cache_.alpha.data(), m)) {
        for (int j = 0; j < n; ++j) out(i0 + j, 0) = m[j] + cache_.offset[0];
        continue;
      }
      shape_group(cache_, X, i0, n, F.data());
      for (Eigen::Index p = 0; p < P; ++p) {
        mean_group(cache_.alpha.col(p).data(), M, F.data(), m);
        for (int j = 0; j < n; ++j) out(i0 + j, p) = m[j] + cache_.offset[p];
      }
    }
  }
  return out;
}

void GaussianProcess::predict(const Eigen::MatrixXd& X, Eigen::MatrixXd& mean, Eigen::MatrixXd& var,
                              bool include_noise) const {
  check_fitted("predict");
  check_inputs(X, "X");
  const Eigen::Index N = X.rows(), P = outputs_;
  mean.resize(N, P);
  var.resize(N, P);
  if (cache_.G_shape == 2 && !cache_.G_packed.empty()) {
    const Eigen::Index M = cache_.basis.rows();
    const Eigen::Index ngroups = (N + kGroup - 1) / kGroup;
#pragma omp parallel num_threads(threads_for(N, opt_.threads))
    {
      std::vector<double> F(static_cast<std::size_t>(M) * kGroup);
      alignas(64) double q[kGroup], m[kGroup];
#pragma omp for schedule(static)
      for (Eigen::Index g = 0; g < ngroups; ++g) {
        const Eigen::Index i0 = g * kGroup;
        const int n = static_cast<int>(std::min<Eigen::Index>(kGroup, N - i0));
        shape_group(cache_, X, i0, n, F.data());
        for (Eigen::Index p = 0; p < P; ++p) {
          mean_group(cache_.alpha.col(p).data(), M, F.data(), m);
          for (int j = 0; j < n; ++j) mean(i0 + j, p) = m[j] + cache_.offset[p];
        }
        quad_group(cache_.G_packed.data(), M, F.data(), q);
        for (int j = 0; j < n; ++j) {
          const double v = std::max(1.0 - q[j], 0.0);  // never negative, NaN-free for finite F
          for (Eigen::Index p = 0; p < P; ++p)
            var(i0 + j, p) = v * cache_.var_f0[p] + (include_noise ? cache_.noise[p] : 0.0);
        }
      }
    }
    return;
  }
  const Eigen::Index nblocks = (N + kBlock - 1) / kBlock;
#pragma omp parallel num_threads(threads_for(N, opt_.threads))
  {
    Eigen::MatrixXd F, H;
    Eigen::ArrayXd v;
#pragma omp for schedule(static)
    for (Eigen::Index b = 0; b < nblocks; ++b) {
      const Eigen::Index i0 = b * kBlock, n = std::min<Eigen::Index>(kBlock, N - i0);
      shape_block(cache_, X, i0, n, F);
      mean.middleRows(i0, n).noalias() = F.transpose() * cache_.alpha;
      mean.middleRows(i0, n).rowwise() += cache_.offset;
      apply_factor(cache_, F, H);
      v = (1.0 - H.colwise().squaredNorm().array()).max(0.0).transpose();
      for (Eigen::Index p = 0; p < P; ++p) {
        var.col(p).segment(i0, n) = (v * cache_.var_f0[p]).matrix();
        if (include_noise) var.col(p).segment(i0, n).array() += cache_.noise[p];
      }
    }
  }
}

Eigen::VectorXd GaussianProcess::log_predictive_density(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) const {
  check_fitted("log_predictive_density");
  check_inputs(X, "X");
  if (Y.rows() != X.rows() || Y.cols() != outputs_)
    throw std::invalid_argument("Y: expected shape (" + std::to_string(X.rows()) + ", " +
                                std::to_string(outputs_) + "), got (" + std::to_string(Y.rows()) + ", " +
                                std::to_string(Y.cols()) + ")");
  if (!Y.allFinite()) throw std::invalid_argument("Y: contains NaN or infinity");
  Eigen::MatrixXd m, v;
  predict(X, m, v, true);
  Eigen::VectorXd lp = Eigen::VectorXd::Zero(X.rows());
  for (Eigen::Index p = 0; p < outputs_; ++p) {
    // Floor keeps a noise-free model at a training input finite.
    const double floor = 1e-12 * std::max(cache_.var_f0.size() > p ? cache_.var_f0[p] : 1.0, 1e-300);
    const Eigen::ArrayXd vv = v.col(p).array().max(floor);
    lp.array() += -0.5 * (kLog2Pi + vv.log() + (Y.col(p) - m.col(p)).array().square() / vv);
  }
  return lp;
}

std::vector<Eigen::MatrixXd> GaussianProcess::sample(const Eigen::MatrixXd& X, int n_samples, std::mt19937_64& rng,
                                                     bool include_noise) const {
  if (n_samples < 1) throw std::invalid_argument("n_samples: must be >= 1");
  Eigen::MatrixXd m, v;
  predict(X, m, v, include_noise);
  const Eigen::MatrixXd sd = v.cwiseMax(0.0).cwiseSqrt();
  std::normal_distribution<double> nd(0.0, 1.0);
  std::vector<Eigen::MatrixXd> out(n_samples, Eigen::MatrixXd(m.rows(), m.cols()));
  for (int s = 0; s < n_samples; ++s)
    for (Eigen::Index i = 0; i < m.rows(); ++i)
      for (Eigen::Index p = 0; p < m.cols(); ++p) out[s](i, p) = m(i, p) + sd(i, p) * nd(rng);
  return out;
}

Eigen::MatrixXd GaussianProcess::predict_cov(const Eigen::MatrixXd& X, int output, bool include_noise) const {
  check_fitted("predict_cov");
  check_inputs(X, "X");
  if (output < 0 || output >= outputs_) throw std::invalid_argument("output: out of range");
  Eigen::MatrixXd F;
  shape_block(cache_, X, 0, X.rows(), F);
  Eigen::MatrixXd H;
  apply_factor(cache_, F, H);
  Eigen::MatrixXd Xs = X.array().rowwise() * cache_.inv_ls.transpose().array();
  Eigen::MatrixXd Kxx = detail::sq_dist(Xs, Xs);
  Kernel k;
  k.type = cache_.type;
  k.shape_inplace(Kxx);
  Kxx.noalias() -= H.transpose() * H;
  Kxx *= cache_.var_f0[output];
  if (include_noise) Kxx.diagonal().array() += cache_.noise[output];
  return Kxx;
}

std::vector<Eigen::MatrixXd> GaussianProcess::sample_joint(const Eigen::MatrixXd& X, int n_samples,
                                                           std::mt19937_64& rng, bool include_noise) const {
  if (n_samples < 1) throw std::invalid_argument("n_samples: must be >= 1");
  const Eigen::MatrixXd m = predict_mean(X);
  const Eigen::Index N = X.rows();
  std::vector<Eigen::MatrixXd> out(n_samples, m);
  std::normal_distribution<double> nd(0.0, 1.0);
  for (Eigen::Index p = 0; p < outputs_; ++p) {
    const Eigen::MatrixXd C = predict_cov(X, static_cast<int>(p), include_noise);
    const double scale = std::max(C.diagonal().maxCoeff(), 1e-300);
    const Eigen::MatrixXd L = robust_cholesky(C, 0.0, scale, "sample_joint", nullptr, 1e-4);
    Eigen::VectorXd z(N);
    for (int s = 0; s < n_samples; ++s) {
      for (Eigen::Index i = 0; i < N; ++i) z[i] = nd(rng);
      out[s].col(p) += L.triangularView<Eigen::Lower>() * z;
    }
  }
  return out;
}

// ---- independent outputs -----------------------------------------------------------------
IndependentOutputsGP::IndependentOutputsGP(GPOptions options, Factory factory)
    : GaussianProcess(std::move(options)), factory_(std::move(factory)) {
  if (!factory_) throw std::invalid_argument("factory: is empty");
}

void IndependentOutputsGP::fit(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) {
  set_training_data(X, Y);
  models_.clear();
  lml_ = 0.0;
  for (int p = 0; p < outputs_; ++p) {
    models_.push_back(factory_());
    models_.back()->fit(X, Y.col(p));
    lml_ += models_.back()->log_marginal_likelihood();
  }
  fitted_ = true;
}

Eigen::MatrixXd IndependentOutputsGP::predict_mean(const Eigen::MatrixXd& X) const {
  check_fitted("predict_mean");
  check_inputs(X, "X");
  Eigen::MatrixXd out(X.rows(), outputs_);
  for (int p = 0; p < outputs_; ++p) out.col(p) = models_[p]->predict_mean(X);
  return out;
}

void IndependentOutputsGP::predict(const Eigen::MatrixXd& X, Eigen::MatrixXd& mean, Eigen::MatrixXd& var,
                                   bool include_noise) const {
  check_fitted("predict");
  check_inputs(X, "X");
  mean.resize(X.rows(), outputs_);
  var.resize(X.rows(), outputs_);
  Eigen::MatrixXd m, v;
  for (int p = 0; p < outputs_; ++p) {
    models_[p]->predict(X, m, v, include_noise);
    mean.col(p) = m;
    var.col(p) = v;
  }
}

Eigen::MatrixXd IndependentOutputsGP::predict_cov(const Eigen::MatrixXd& X, int output, bool include_noise) const {
  check_fitted("predict_cov");
  if (output < 0 || output >= outputs_) throw std::invalid_argument("output: out of range");
  return models_[output]->predict_cov(X, 0, include_noise);
}

std::vector<Eigen::MatrixXd> IndependentOutputsGP::sample_joint(const Eigen::MatrixXd& X, int n_samples,
                                                                std::mt19937_64& rng, bool include_noise) const {
  check_fitted("sample_joint");
  std::vector<Eigen::MatrixXd> out(n_samples, Eigen::MatrixXd(X.rows(), outputs_));
  for (int p = 0; p < outputs_; ++p) {
    const auto s = models_[p]->sample_joint(X, n_samples, rng, include_noise);
    for (int k = 0; k < n_samples; ++k) out[k].col(p) = s[k];
  }
  return out;
}

double IndependentOutputsGP::log_marginal_likelihood() const { return lml_; }

Eigen::VectorXd IndependentOutputsGP::parameters() const {
  check_fitted("parameters");
  std::vector<Eigen::VectorXd> parts;
  Eigen::Index n = 0;
  for (const auto& m : models_) {
    parts.push_back(m->parameters());
    n += parts.back().size();
  }
  Eigen::VectorXd t(n);
  n = 0;
  for (const auto& p : parts) {
    t.segment(n, p.size()) = p;
    n += p.size();
  }
  return t;
}

double IndependentOutputsGP::objective(const Eigen::VectorXd& theta, Eigen::VectorXd& grad) const {
  check_fitted("objective");
  grad.resize(theta.size());
  double f = 0.0;
  Eigen::Index n = 0;
  for (const auto& m : models_) {
    const Eigen::Index k = m->parameters().size();
    if (n + k > theta.size()) throw std::invalid_argument("theta: too short");
    Eigen::VectorXd g;
    f += m->objective(theta.segment(n, k), g);
    grad.segment(n, k) = g;
    n += k;
  }
  return f;
}

}  // namespace bayesgrasp::gp

#include "bayesgrasp/gp/exact_gp.hpp"

#include <cmath>
#include <stdexcept>

#include "bayesgrasp/gp/linalg.hpp"

namespace bayesgrasp::gp {

namespace {
constexpr double kLog2Pi = 1.8378770664093453;

struct ExactEval {
  Eigen::MatrixXd L;      // Cholesky of K + noise I (+ jitter)
  Eigen::MatrixXd alpha;  // (N, P) (K + noise I)^-1 (y - c)
  double lml = 0.0;
  double jitter = 0.0;
};

// The log marginal likelihood (and, if grad is non-null, the gradient of its negative with the
// mean constants' entries for MeanType::Constant) at the given hyper-parameters.
ExactEval exact_eval(const Eigen::MatrixXd& Xn, const Eigen::MatrixXd& Yn, const Kernel& k, double noise,
                     const Eigen::VectorXd& c, double jitter0, Eigen::VectorXd* grad, MeanType mean) {
  const Eigen::Index N = Xn.rows(), P = Yn.cols(), D = Xn.cols();
  const double var = k.variance();
  const Eigen::RowVectorXd inv_ls = (-k.log_lengthscale.array()).exp().matrix().transpose();
  const Eigen::MatrixXd Xs = Xn.array().rowwise() * inv_ls.array();
  Eigen::MatrixXd R2 = detail::sq_dist(Xs, Xs);
  Eigen::MatrixXd K = R2;
  k.shape_inplace(K);
  K *= var;
  Eigen::MatrixXd Ky = K;
  Ky.diagonal().array() += noise;
  ExactEval e;
  e.L = robust_cholesky(Ky, jitter0 > 0 && noise == 0.0 ? jitter0 : 0.0, var, "ExactGP covariance", &e.jitter);
  const Eigen::MatrixXd& Lc = e.L;
  const auto Lt = Lc.triangularView<Eigen::Lower>();
  const Eigen::MatrixXd r = Yn.rowwise() - c.transpose();
  e.alpha = Lt.solve(r);
  const double quad = e.alpha.squaredNorm();
  Lt.transpose().solveInPlace(e.alpha);
  e.lml = -0.5 * quad - double(P) * e.L.diagonal().array().log().sum() - 0.5 * double(N * P) * kLog2Pi;
  if (grad) {
    // dL/dK = 1/2 (alpha alpha^T - P K^-1)
    Eigen::MatrixXd W = Eigen::MatrixXd::Identity(N, N);
    Lt.solveInPlace(W);
    Lt.transpose().solveInPlace(W);
    W *= -double(P);
    W.noalias() += e.alpha * e.alpha.transpose();
    W *= 0.5;
    const int nc = mean == MeanType::Constant ? static_cast<int>(P) : 0;
    grad->setZero(D + 2 + nc);
    Eigen::VectorXd gls = Eigen::VectorXd::Zero(D);
    double gvar = 0.0;
    detail::contract_gradient(k, Xs, Xs, R2, K, W, gls, &gvar, nullptr, nullptr);
    if (e.jitter > 0) gvar += W.trace() * e.jitter * var;  // jitter scales with the variance
    grad->head(D) = -gls;
    (*grad)[D] = -gvar;
    (*grad)[D + 1] = -W.trace() * noise;
    if (nc) grad->segment(D + 2, nc) = -e.alpha.colwise().sum().transpose();
  }
  return e;
}
}  // namespace

ExactGP::ExactGP(GPOptions options) : GaussianProcess(std::move(options)) {}

double ExactGP::objective(const Eigen::VectorXd& theta, Eigen::VectorXd& grad) const {
  check_training_data("objective");
  Kernel k;
  double noise;
  Eigen::VectorXd c;
  unpack(theta, k, noise, c, nullptr);
  const ExactEval e =
      exact_eval(Xn_, Yn_, k, noise, c, opt_.jitter, &grad, opt_.mean);
  return -e.lml;
}

void ExactGP::fit(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) {
  set_training_data(X, Y);
  if (opt_.optimize && opt_.max_iter > 0) optimise(0);
  build_cache();
  fitted_ = true;
}

void ExactGP::build_cache() {
  const ExactEval e = exact_eval(Xn_, Yn_, kernel_, noise_, mean_c_, opt_.jitter, nullptr, MeanType::Zero);
  set_fitted_mean(e.lml, e.jitter, X_, e.alpha);
  const double var = kernel_.variance();
  // var_f = var (1 - |sqrt(var) L^-1 f|^2): keep L / sqrt(var) and solve in prediction (the
  // same N^2 flops per input as multiplying by an explicit inverse, without its N^3 cost at fit).
  cache_.G = e.L / std::sqrt(var);
  cache_.G.triangularView<Eigen::StrictlyUpper>().setZero();
  cache_.factor = VarianceFactor::InverseLower;
  cache_.G_packed.clear();
  cache_.noise = (y_scale_.array().square() * (noise_ + e.jitter * var)).matrix().transpose();
}

}  // namespace bayesgrasp::gp

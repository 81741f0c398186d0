#include "bayesgrasp/gp/sparse_gp.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "bayesgrasp/gp/fitc.hpp"
#include "bayesgrasp/gp/kmeans.hpp"

namespace bayesgrasp::gp {

SparseGP::SparseGP(GPOptions options) : GaussianProcess(std::move(options)) {}

Eigen::VectorXd SparseGP::parameters() const {
  Eigen::VectorXd base = GaussianProcess::parameters();
  if (!opt_.optimize_inducing) return base;
  Eigen::VectorXd t(base.size() + Zn_.size());
  t << base, Eigen::Map<const Eigen::VectorXd>(Zn_.data(), Zn_.size());
  return t;
}

double SparseGP::objective(const Eigen::VectorXd& theta, Eigen::VectorXd& grad) const {
  check_training_data("objective");
  Kernel k;
  double noise;
  Eigen::VectorXd c;
  Eigen::MatrixXd Z = Zn_;
  unpack(theta, k, noise, c, &Z);
  const bool gz = theta.size() > dim_ + 2 + (opt_.mean == MeanType::Constant ? outputs_ : 0);
  if (gz && Z.rows() != Zn_.rows()) throw std::invalid_argument("theta: inducing block has the wrong size");
  const detail::FitcInputs in{Xn_, Yn_, Z, k, noise, c, opt_.jitter, opt_.mean};
  const detail::FitcGradient what =
      gz ? detail::FitcGradient::HyperparametersAndInducing : detail::FitcGradient::Hyperparameters;
  return -detail::fitc_eval(in, what, &grad).lml;
}

double SparseGP::profiled_objective(const Eigen::VectorXd& theta_p, Eigen::VectorXd& grad, double* log_scale) const {
  check_training_data("objective");
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
  const detail::FitcInputs in{Xn_, Yn_, Zn_, k, noise, c, opt_.jitter, opt_.mean};
  const detail::FitcEval e = detail::fitc_eval(in, detail::FitcGradient::Hyperparameters, &g, &ls);
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
  const detail::FitcInputs in{Xn_, Yn_, Zn_, kernel_, noise_, mean_c_, opt_.jitter, MeanType::Zero};
  const detail::FitcEval e = detail::fitc_eval(in, detail::FitcGradient::None, nullptr);
  // mean weights: L^-T LA^-T beta
  Eigen::MatrixXd wts = e.LA.triangularView<Eigen::Lower>().transpose().solve(e.beta);
  e.L.triangularView<Eigen::Lower>().transpose().solveInPlace(wts);
  set_fitted_mean(e.lml, e.jitter, inducing_inputs(), wts);
  const double var = kernel_.variance();
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
  cache_.factor = VarianceFactor::Upper;
  cache_.pack_factor();
  cache_.noise = (y_scale_.array().square() * noise_).matrix().transpose();
}

}  // namespace bayesgrasp::gp

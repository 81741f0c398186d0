#include "bayesgrasp/gp/gaussian_process.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "bayesgrasp/common/parallel.hpp"
#include "bayesgrasp/gp/hyperparameter_fit.hpp"
#include "bayesgrasp/gp/linalg.hpp"

namespace bayesgrasp::gp {

namespace {
constexpr double kLog2Pi = 1.8378770664093453;
}  // namespace

MeanType mean_type_from_string(const std::string& name) {
  if (name == "zero") return MeanType::Zero;
  if (name == "constant") return MeanType::Constant;
  throw std::invalid_argument("mean: expected 'zero' or 'constant', got '" + name + "'");
}
std::string mean_type_name(MeanType type) { return type == MeanType::Zero ? "zero" : "constant"; }

void validate(const GPOptions& o) {
  if (o.lengthscale.size() > 0 &&
      (!(o.lengthscale.array() > 0.0).all() || !o.lengthscale.allFinite()))
    throw std::invalid_argument("lengthscale: must be positive and finite");
  if (!(o.variance > 0.0) || !std::isfinite(o.variance))
    throw std::invalid_argument("variance: must be positive and finite");
  if (!(o.noise >= 0.0) || !std::isfinite(o.noise))
    throw std::invalid_argument("noise: must be non-negative and finite");
  if (o.max_iter < 0) throw std::invalid_argument("max_iter: must be >= 0");
  if (o.n_inducing < 1) throw std::invalid_argument("n_inducing: must be >= 1");
  if (!(o.jitter >= 0.0) || !std::isfinite(o.jitter)) throw std::invalid_argument("jitter: must be >= 0");
  if (o.kmeans_iter < 0) throw std::invalid_argument("kmeans_iter: must be >= 0");
  thread_count(o.threads, "threads");  // validates: 0 = all cores, negative is an error
  if (o.mean_constant.size() > 0 && !o.mean_constant.allFinite())
    throw std::invalid_argument("mean_constant: contains NaN or infinity");
  if (o.inducing.size() > 0 && !o.inducing.allFinite())
    throw std::invalid_argument("inducing: contains NaN or infinity");
}

GaussianProcess::GaussianProcess(GPOptions o) : opt_(std::move(o)) {
  validate(opt_);
  noise_ = opt_.noise;
}

void GaussianProcess::check_fitted(const char* what) const {
  if (!fitted_) throw std::invalid_argument(std::string(what) + ": the model is not fitted; call fit() first");
}

void GaussianProcess::check_training_data(const char* what) const {
  if (Xn_.size() == 0) throw std::invalid_argument(std::string(what) + ": no training data; call fit() first");
}

void GaussianProcess::check_inputs(const Eigen::MatrixXd& X, const char* name) const {
  if (X.cols() != dim_)
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(dim_) + " columns, got " +
                                std::to_string(X.cols()));
  if (!X.allFinite()) throw std::invalid_argument(std::string(name) + ": contains NaN or infinity");
  check_magnitude(X, name);
}

// n_samples x N x P draws beyond 10^8 values (800 MB) only exhaust memory.
void GaussianProcess::check_draw_size(long long n_samples, long long rows, long long outputs) {
  if (n_samples * std::max(rows, 1LL) * std::max(outputs, 1LL) > 100000000LL)
    throw std::invalid_argument("n_samples: " + std::to_string(n_samples) + " draws of " + std::to_string(rows) +
                                " inputs exceed 10^8 values");
}

// Squared distances of inputs beyond 1e150 overflow to infinity (and standardising them loses
// every digit of their spread), so such inputs are refused instead of predicting NaN.
void GaussianProcess::check_magnitude(const Eigen::MatrixXd& X, const char* name) {
  constexpr double kMaxInput = 1e100;
  if (X.size() > 0 && X.cwiseAbs().maxCoeff() > kMaxInput)
    throw std::invalid_argument(std::string(name) + ": values beyond 1e100 in magnitude; rescale the inputs");
}

void GaussianProcess::set_training_data(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) {
  if (X.rows() == 0 || X.cols() == 0) throw std::invalid_argument("X: is empty");
  if (Y.rows() != X.rows())
    throw std::invalid_argument("y: has " + std::to_string(Y.rows()) + " rows but X has " + std::to_string(X.rows()));
  if (Y.cols() == 0) throw std::invalid_argument("y: has no outputs");
  if (!X.allFinite()) throw std::invalid_argument("X: contains NaN or infinity");
  if (!Y.allFinite()) throw std::invalid_argument("y: contains NaN or infinity");
  check_magnitude(X, "X");
  if (Y.cwiseAbs().maxCoeff() > 1e100)
    throw std::invalid_argument("y: values beyond 1e100 in magnitude; rescale the outputs");
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

void GaussianProcess::set_fitted_mean(double lml, double jitter, const Eigen::MatrixXd& basis_inputs,
                                      const Eigen::MatrixXd& weights) {
  lml_ = lml;
  info_.log_marginal_likelihood = lml;
  info_.jitter_used = jitter;
  const double var = kernel_.variance();
  cache_.type = kernel_.type;
  cache_.inv_ls = (kernel_.log_lengthscale.array().exp() * x_scale_.array()).inverse().matrix();
  cache_.basis = basis_inputs.array().rowwise() * cache_.inv_ls.transpose().array();
  cache_.alpha = (weights * var).array().rowwise() * y_scale_.transpose().array();
  cache_.offset = (y_mean_ + y_scale_.cwiseProduct(mean_c_)).transpose();
  cache_.var_f0 = (y_scale_.array().square() * var).matrix().transpose();
}

Eigen::VectorXd GaussianProcess::optimise(int n_extra) {
  const FitObjective kind = opt_.profile_scale && n_extra == 0 && supports_profile() ? FitObjective::ProfiledScale
                                                                                       : FitObjective::Full;
  info_ = FitInfo{};
  HyperparameterFit fit = fit_hyperparameters(*this, parameters(), Xn_, Yn_, opt_.max_iter, kind);
  info_ = fit.info;
  Eigen::VectorXd c;
  unpack(fit.theta, kernel_, noise_, c, nullptr);
  mean_c_ = c;
  return fit.theta;
}

double GaussianProcess::profiled_objective(const Eigen::VectorXd&, Eigen::VectorXd&, double*) const {
  throw std::logic_error("profiled_objective: not supported by this model");
}

void GaussianProcess::set_threads(int threads) {
  thread_count(threads, "threads");
  opt_.threads = threads;
}

int GaussianProcess::threads() const { return thread_count(opt_.threads, "threads"); }

// ---- prediction on the cache (prediction.hpp) ---------------------------------------------
Eigen::MatrixXd GaussianProcess::predict_mean(const Eigen::MatrixXd& X) const {
  check_fitted("predict_mean");
  check_inputs(X, "X");
  return gp::predict_mean(cache_, X, threads());
}

void GaussianProcess::predict(const Eigen::MatrixXd& X, Eigen::MatrixXd& mean, Eigen::MatrixXd& var,
                              Predictive what) const {
  check_fitted("predict");
  check_inputs(X, "X");
  predict_mean_var(cache_, X, what, threads(), mean, var);
}

Eigen::MatrixXd GaussianProcess::predict_cov(const Eigen::MatrixXd& X, int output, Predictive what) const {
  check_fitted("predict_cov");
  check_inputs(X, "X");
  if (output < 0 || output >= outputs_) throw std::invalid_argument("output: out of range");
  return gp::predict_cov(cache_, X, output, what);
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
  predict(X, m, v, Predictive::Observation);
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
                                                     Predictive what) const {
  if (n_samples < 1) throw std::invalid_argument("n_samples: must be >= 1");
  check_draw_size(n_samples, X.rows(), outputs_);
  Eigen::MatrixXd m, v;
  predict(X, m, v, what);
  const Eigen::MatrixXd sd = v.cwiseMax(0.0).cwiseSqrt();
  std::normal_distribution<double> nd(0.0, 1.0);
  std::vector<Eigen::MatrixXd> out(n_samples, Eigen::MatrixXd(m.rows(), m.cols()));
  for (int s = 0; s < n_samples; ++s)
    for (Eigen::Index i = 0; i < m.rows(); ++i)
      for (Eigen::Index p = 0; p < m.cols(); ++p) out[s](i, p) = m(i, p) + sd(i, p) * nd(rng);
  return out;
}

std::vector<Eigen::MatrixXd> GaussianProcess::sample_joint(const Eigen::MatrixXd& X, int n_samples,
                                                           std::mt19937_64& rng, Predictive what) const {
  if (n_samples < 1) throw std::invalid_argument("n_samples: must be >= 1");
  check_draw_size(n_samples, X.rows(), outputs_);
  const Eigen::MatrixXd m = predict_mean(X);
  const Eigen::Index N = X.rows();
  std::vector<Eigen::MatrixXd> out(n_samples, m);
  if (N == 0) return out;  // (n_samples, 0, P): no covariance to factor
  std::normal_distribution<double> nd(0.0, 1.0);
  for (Eigen::Index p = 0; p < outputs_; ++p) {
    const Eigen::MatrixXd C = predict_cov(X, static_cast<int>(p), what);
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

}  // namespace bayesgrasp::gp

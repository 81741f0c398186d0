#include "bayesgrasp/gp/independent_outputs_gp.hpp"

#include <stdexcept>

namespace bayesgrasp::gp {

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
                                   Predictive what) const {
  check_fitted("predict");
  check_inputs(X, "X");
  mean.resize(X.rows(), outputs_);
  var.resize(X.rows(), outputs_);
  Eigen::MatrixXd m, v;
  for (int p = 0; p < outputs_; ++p) {
    models_[p]->predict(X, m, v, what);
    mean.col(p) = m;
    var.col(p) = v;
  }
}

Eigen::MatrixXd IndependentOutputsGP::predict_cov(const Eigen::MatrixXd& X, int output, Predictive what) const {
  check_fitted("predict_cov");
  if (output < 0 || output >= outputs_) throw std::invalid_argument("output: out of range");
  return models_[output]->predict_cov(X, 0, what);
}

std::vector<Eigen::MatrixXd> IndependentOutputsGP::sample_joint(const Eigen::MatrixXd& X, int n_samples,
                                                                std::mt19937_64& rng, Predictive what) const {
  check_fitted("sample_joint");
  std::vector<Eigen::MatrixXd> out(n_samples, Eigen::MatrixXd(X.rows(), outputs_));
  for (int p = 0; p < outputs_; ++p) {
    const auto s = models_[p]->sample_joint(X, n_samples, rng, what);
    for (int k = 0; k < n_samples; ++k) out[k].col(p) = s[k];
  }
  return out;
}

double IndependentOutputsGP::log_marginal_likelihood() const {
  check_fitted("log_marginal_likelihood");
  return lml_;
}

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

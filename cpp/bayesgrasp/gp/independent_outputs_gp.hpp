// One GP per output column, each with its own hyper-parameters (and inducing inputs), behind
// the common interface of gaussian_process.hpp. The models come from a factory (ExactGP or
// SparseGP with the options the caller chooses).
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "bayesgrasp/gp/gaussian_process.hpp"

namespace bayesgrasp::gp {

class IndependentOutputsGP : public GaussianProcess {
 public:
  using Factory = std::function<std::unique_ptr<GaussianProcess>()>;
  IndependentOutputsGP(GPOptions options, Factory factory);
  void fit(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) override;
  Eigen::MatrixXd predict_mean(const Eigen::MatrixXd& X) const override;
  void predict(const Eigen::MatrixXd& X, Eigen::MatrixXd& mean, Eigen::MatrixXd& var,
               Predictive what = Predictive::Latent) const override;
  Eigen::MatrixXd predict_cov(const Eigen::MatrixXd& X, int output = 0,
                              Predictive what = Predictive::Latent) const override;
  std::vector<Eigen::MatrixXd> sample_joint(const Eigen::MatrixXd& X, int n_samples, std::mt19937_64& rng,
                                            Predictive what = Predictive::Observation) const override;
  double log_marginal_likelihood() const override;
  Eigen::VectorXd parameters() const override;
  double objective(const Eigen::VectorXd& theta, Eigen::VectorXd& grad) const override;
  int n_models() const { return static_cast<int>(models_.size()); }
  const GaussianProcess& model(int p) const { return *models_.at(p); }

 private:
  Factory factory_;
  std::vector<std::unique_ptr<GaussianProcess>> models_;
};

}  // namespace bayesgrasp::gp

// Gaussian-process regression: the common interface of ExactGP and SparseGP (FITC).
//
// API in brief (rows of X are inputs, rows of Y the output vectors; P outputs share one set of
// hyper-parameters and one factorisation; IndependentOutputsGP gives each output its own):
//
//   GPOptions o;  o.kernel = KernelType::SquaredExponential;  o.n_inducing = 200;
//   SparseGP gp(o);                      // or ExactGP gp(o);
//   gp.fit(X, Y);                        // X (N, D), Y (N, P); optimises hyper-parameters if o.optimize
//   Eigen::MatrixXd m = gp.predict_mean(Xs);          // (Ns, P) fast path (fused kernel + dot)
//   gp.predict(Xs, mean, var);                        // (Ns, P) each; var of the latent f (of an
//                                                     //  observation with Predictive::Observation)
//   Eigen::VectorXd lp = gp.log_predictive_density(Xs, Ys);  // (Ns,): sum over outputs of
//                                                     //  log N(Ys(i,p) | mean, var_f + noise)
//   std::mt19937_64 rng(seed);  auto S = gp.sample(Xs, n, rng);  // n matrices (Ns, P), marginal
//   const GaussianProcess& base = gp;                 // all of the above through the base class
//
// Normalisation (o.normalize_x / o.normalize_y): inputs and outputs are standardised before the
// fit; the hyper-parameters (lengthscales, variance, noise, mean constant) live in that
// standardised space; every prediction is returned in the original units. All predictions are
// const and thread-safe; batches of >= 2048 inputs use o.threads OpenMP threads (0 = all cores,
// common/parallel.hpp).
// Errors: std::invalid_argument for bad arguments and for calls that need a fitted model,
// std::runtime_error for numerical failure (never silent NaN).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "bayesgrasp/gp/kernel.hpp"
#include "bayesgrasp/gp/prediction.hpp"

namespace bayesgrasp::gp {

enum class MeanType { Zero, Constant };
MeanType mean_type_from_string(const std::string& name);  ///< "zero" or "constant"
std::string mean_type_name(MeanType type);

struct GPOptions {
  KernelType kernel = KernelType::SquaredExponential;
  Eigen::VectorXd lengthscale;   ///< initial lengthscales (D,) or (1,) = isotropic start; empty = 1
  double variance = 1.0;         ///< initial signal variance
  double noise = 1e-2;           ///< initial noise variance (>= 0; 0 = noise-free, with jitter)
  MeanType mean = MeanType::Zero;
  Eigen::VectorXd mean_constant; ///< initial mean constants (P,) for MeanType::Constant; empty = auto
  bool optimize = true;          ///< maximise the log marginal likelihood in fit()
  int max_iter = 200;            ///< L-BFGS iterations
  bool normalize_x = true;
  bool normalize_y = true;
  double jitter = 1e-8;          ///< initial diagonal jitter relative to the signal variance
  int threads = 1;               ///< OpenMP threads for large prediction batches (0 = all cores)
  // SparseGP only
  int n_inducing = 200;          ///< M (capped at the number of distinct training inputs)
  bool optimize_inducing = false;
  /// SparseGP: optimise with the signal variance profiled out. The FITC covariance scales
  /// with (variance, noise) together, so for fixed lengthscales and noise/variance ratio the
  /// best overall scale is quad / (N P) in closed form; L-BFGS then searches one dimension
  /// fewer and reaches the same optimum in fewer evaluations (BENCHMARKS.md).
  bool profile_scale = true;
  std::uint64_t seed = 0;        ///< k-means++ seed for the inducing inputs
  Eigen::MatrixXd inducing;      ///< (M, D) initial inducing inputs in input units; empty = k-means++
  int kmeans_iter = 10;          ///< Lloyd iterations after k-means++ seeding
};

/// Throws std::invalid_argument naming the first bad field.
void validate(const GPOptions& options);

/// Result of fit(): how the optimisation went.
struct FitInfo {
  int iterations = 0;           ///< L-BFGS-B iterations (0 without optimisation)
  int evaluations = 0;          ///< objective + gradient evaluations
  double log_marginal_likelihood = 0.0;  ///< at the fitted hyper-parameters (standardised outputs)
  double jitter_used = 0.0;     ///< final jitter (relative) that made the Cholesky succeed
  std::string message;          ///< "converged", "stopped: <reason>", or empty without optimisation
};

class GaussianProcess {
 public:
  explicit GaussianProcess(GPOptions options);
  virtual ~GaussianProcess() = default;

  /// Fits to X (N, D) and Y (N, P). Throws std::invalid_argument on bad shapes or non-finite data.
  virtual void fit(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) = 0;

  bool fitted() const { return fitted_; }
  int input_dim() const { return dim_; }
  int output_dim() const { return outputs_; }

  // ---- prediction (original units) ----
  /// Predictive mean at the rows of X: (N, P).
  virtual Eigen::MatrixXd predict_mean(const Eigen::MatrixXd& X) const;
  /// Predictive mean and variance, each (N, P): the variance of f, or of an observation.
  virtual void predict(const Eigen::MatrixXd& X, Eigen::MatrixXd& mean, Eigen::MatrixXd& var,
                       Predictive what = Predictive::Latent) const;
  /// Log density of the observed rows of Y at the rows of X under the predictive distribution
  /// with noise: sum over outputs of log N(Y(i,p) | mean(i,p), var(i,p) + noise_p). (N,)
  virtual Eigen::VectorXd log_predictive_density(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) const;
  /// n_samples independent draws per input from the marginal predictive distribution (of f or
  /// of an observation): n_samples matrices (N, P).
  virtual std::vector<Eigen::MatrixXd> sample(const Eigen::MatrixXd& X, int n_samples, std::mt19937_64& rng,
                                              Predictive what = Predictive::Observation) const;
  /// Joint draws over the rows of X (outputs independent): n_samples matrices (N, P).
  virtual std::vector<Eigen::MatrixXd> sample_joint(const Eigen::MatrixXd& X, int n_samples, std::mt19937_64& rng,
                                                    Predictive what = Predictive::Observation) const;
  /// Predictive covariance (N, N) of output p (of f, plus the noise on the diagonal for
  /// Predictive::Observation).
  virtual Eigen::MatrixXd predict_cov(const Eigen::MatrixXd& X, int output = 0,
                                      Predictive what = Predictive::Latent) const;

  // ---- hyper-parameters and objective (standardised space) ----
  virtual double log_marginal_likelihood() const {
    check_fitted("log_marginal_likelihood");
    return lml_;
  }
  const Kernel& kernel() const { return kernel_; }
  double noise() const { return noise_; }
  const Eigen::VectorXd& mean_constant() const { return mean_c_; }  ///< (P,), zeros for MeanType::Zero
  const GPOptions& options() const { return opt_; }
  const FitInfo& fit_info() const { return info_; }
  /// Sets the threads of large prediction batches (0 = all cores); throws for a negative count.
  void set_threads(int threads);
  /// The threads large prediction batches use: options().threads by the one thread rule.
  int threads() const;

  /// Normalisation used in the fit: x_std = (x - x_mean) / x_scale, y likewise.
  const Eigen::VectorXd& x_mean() const { return x_mean_; }
  const Eigen::VectorXd& x_scale() const { return x_scale_; }
  const Eigen::VectorXd& y_mean() const { return y_mean_; }
  const Eigen::VectorXd& y_scale() const { return y_scale_; }
  const Eigen::MatrixXd& X_train() const { return X_; }  ///< raw training inputs
  const Eigen::MatrixXd& Y_train() const { return Y_; }  ///< raw training outputs

  /// Packed parameter vector theta = [log lengthscales (D), log variance, log noise,
  /// mean constants (P, Constant mean only), inducing inputs (M*D column-major, standardised
  /// units; SparseGP with optimize_inducing only)].
  virtual Eigen::VectorXd parameters() const;
  /// Negative log marginal likelihood at theta and its analytic gradient (for the current
  /// training data), without changing the model.
  virtual double objective(const Eigen::VectorXd& theta, Eigen::VectorXd& grad) const = 0;
  /// The objective with the signal variance profiled out (see GPOptions::profile_scale):
  /// theta_p = theta without the log variance, its log noise entry read as log(noise /
  /// variance); the gradient is that of the profiled objective; *log_scale = the optimal
  /// log variance. Models without it throw std::logic_error (supports_profile() is false).
  virtual bool supports_profile() const { return false; }
  virtual double profiled_objective(const Eigen::VectorXd& theta_p, Eigen::VectorXd& grad, double* log_scale) const;

 protected:
  /// Throw std::invalid_argument naming `what` unless the model is fitted / has training data
  /// (the objectives are evaluated during the fit, before the model counts as fitted).
  void check_fitted(const char* what) const;
  void check_training_data(const char* what) const;
  void check_inputs(const Eigen::MatrixXd& X, const char* name) const;
  static void check_magnitude(const Eigen::MatrixXd& X, const char* name);
  static void check_draw_size(long long n_samples, long long rows, long long outputs);
  /// Standardises X, Y into Xn_, Yn_ and sets the normalisation; validates.
  void set_training_data(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y);
  /// Runs the hyper-parameter fit (hyperparameter_fit.hpp) from parameters(); n_inducing_params
  /// > 0 when theta carries the inducing inputs too. Returns the best theta found and sets
  /// kernel_, noise_, mean_c_ and the fit's info from it.
  Eigen::VectorXd optimise(int n_inducing_params);
  /// Records a fit's log marginal likelihood and jitter and sets the mean part of the prediction
  /// cache from the basis inputs (M, D) in raw units and the standardised weights (M, P):
  /// kernel type, scaled basis, weights in raw units (times the variance), offset, prior variance.
  void set_fitted_mean(double lml, double jitter, const Eigen::MatrixXd& basis_inputs, const Eigen::MatrixXd& weights);
  /// Splits theta into the hyper-parameters (and the inducing inputs if Z is non-null).
  void unpack(const Eigen::VectorXd& theta, Kernel& k, double& noise, Eigen::VectorXd& c,
              Eigen::MatrixXd* Z) const;

  GPOptions opt_;
  Kernel kernel_;
  double noise_ = 1e-2;
  Eigen::VectorXd mean_c_;
  int dim_ = 0, outputs_ = 0;
  bool fitted_ = false;
  double lml_ = 0.0;
  FitInfo info_;
  Eigen::MatrixXd X_, Y_;    // raw
  Eigen::MatrixXd Xn_, Yn_;  // standardised
  Eigen::VectorXd x_mean_, x_scale_, y_mean_, y_scale_;
  PredictionCache cache_;
};

}  // namespace bayesgrasp::gp

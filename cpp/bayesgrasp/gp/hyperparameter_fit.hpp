// The hyper-parameter fit of the GP models: maximise the log marginal likelihood over
// theta = [log lengthscales, log variance, log noise, mean constants, inducing inputs] by
// L-BFGS-B (LBFGSpp, SciPy's default tolerances) with analytic gradients, inside a box relative
// to the data's scales. With the profiled scale (GPOptions::profile_scale) the signal variance is
// dropped from theta and set in closed form at every evaluation (SparseGP::profiled_objective).
#pragma once

#include <Eigen/Core>

#include "bayesgrasp/gp/gaussian_process.hpp"

namespace bayesgrasp::gp {

/// Which objective L-BFGS-B minimises.
enum class FitObjective {
  Full,           ///< objective(theta)
  ProfiledScale,  ///< profiled_objective(theta without the log variance)
};

struct HyperparameterFit {
  Eigen::VectorXd theta;  ///< the best parameters found, in the full layout of parameters()
  FitInfo info;           ///< iterations, evaluations and message (the likelihood is filled by the model)
};

/// Minimises model's negative log marginal likelihood from theta0 (the full layout) for at most
/// max_iter L-BFGS-B iterations. Xn, Yn: the standardised training data (they set the box
/// bounds). Throws std::runtime_error if the objective cannot be evaluated at all.
HyperparameterFit fit_hyperparameters(const GaussianProcess& model, const Eigen::VectorXd& theta0,
                                      const Eigen::MatrixXd& Xn, const Eigen::MatrixXd& Yn, int max_iter,
                                      FitObjective objective);

}  // namespace bayesgrasp::gp

// Bindings for the gp concept: GPOptions and FitInfo as classes, ExactGP and SparseGP (FITC)
// built from a GPOptions. Thin: convert, release the GIL, call C++; the core validates (its
// std::invalid_argument becomes ValueError). The scikit-learn-style estimators live in
// python/bayesgrasp/gp.py.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <random>

#include "bayesgrasp/gp/gp.hpp"
#include "options.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace py = pybind11;
using namespace py::literals;
using namespace bayesgrasp::gp;

namespace {

Eigen::MatrixXd cm(const RowMatrixXd& m) { return m; }

/// y may be 1-D (N,) or 2-D (N, P) (the model checks N against its inputs).
Eigen::MatrixXd outputs(const DArray& y, const char* name) {
  if (y.ndim() == 1) return vector(y, name);
  return cm(matrix(y, name));
}

/// Prediction inputs: any 2-D finite array (the model checks the column count once fitted).
Eigen::MatrixXd inputs(const DArray& X) { return cm(matrix(X, "X", -1, true)); }

Predictive predictive(bool include_noise) { return include_noise ? Predictive::Observation : Predictive::Latent; }

py::array_t<double> stack(const std::vector<Eigen::MatrixXd>& s) {
  const py::ssize_t S = s.size(), N = S ? s[0].rows() : 0, P = S ? s[0].cols() : 0;
  py::array_t<double> out({S, N, P});
  auto r = out.mutable_unchecked<3>();
  for (py::ssize_t k = 0; k < S; ++k)
    for (py::ssize_t i = 0; i < N; ++i)
      for (py::ssize_t p = 0; p < P; ++p) r(k, i, p) = s[k](i, p);
  return out;
}

void bind_options(py::module_& m) {
  OptionClass<GPOptions>(m, "GPOptions",
                         "Options of ExactGP and SparseGP: the kernel, initial hyper-parameters, the fit and\n"
                         "(SparseGP) the inducing inputs. Checked when a model is built from them.")
      .property(
          "kernel", [](const GPOptions& o) { return kernel_type_name(o.kernel); },
          [](GPOptions& o, const std::string& s) { o.kernel = kernel_type_from_string(s); }, "str",
          "'se' (squared exponential) or 'matern52'.")
      .field("lengthscale", &GPOptions::lengthscale, "numpy.ndarray",
             "Initial lengthscales (D,) or (1,) (isotropic start); empty = 1.")
      .field("variance", &GPOptions::variance, "float", "Initial signal variance, > 0.")
      .field("noise", &GPOptions::noise, "float", "Initial noise variance, >= 0 (0 = noise-free, with jitter).")
      .property(
          "mean", [](const GPOptions& o) { return mean_type_name(o.mean); },
          [](GPOptions& o, const std::string& s) { o.mean = mean_type_from_string(s); }, "str",
          "'zero' or 'constant' (one fitted constant per output).")
      .field("mean_constant", &GPOptions::mean_constant, "numpy.ndarray",
             "Initial mean constants (P,) for mean 'constant'; empty = automatic.")
      .field("optimize", &GPOptions::optimize, "bool", "Maximise the log marginal likelihood in fit (L-BFGS-B).")
      .field("max_iter", &GPOptions::max_iter, "int", "L-BFGS-B iterations, >= 0.")
      .field("normalize_x", &GPOptions::normalize_x, "bool", "Standardise the inputs before the fit.")
      .field("normalize_y", &GPOptions::normalize_y, "bool", "Standardise the outputs before the fit.")
      .field("jitter", &GPOptions::jitter, "float", "Initial diagonal jitter relative to the signal variance, >= 0.")
      .field("threads", &GPOptions::threads, "int",
             "OpenMP threads for prediction batches of >= 2048 inputs (0 = all cores).")
      .field("n_inducing", &GPOptions::n_inducing, "int",
             "SparseGP: inducing inputs M, >= 1 (capped at the distinct training inputs).")
      .field("optimize_inducing", &GPOptions::optimize_inducing, "bool", "SparseGP: optimise the inducing inputs too.")
      .field("profile_scale", &GPOptions::profile_scale, "bool",
             "SparseGP: optimise with the signal variance profiled out.")
      .field("seed", &GPOptions::seed, "int", "SparseGP: k-means++ seed for the inducing inputs.")
      .field("inducing", &GPOptions::inducing, "numpy.ndarray",
             "SparseGP: initial inducing inputs (M, D) in input units; empty = k-means++.")
      .field("kmeans_iter", &GPOptions::kmeans_iter, "int",
             "SparseGP: Lloyd iterations after the k-means++ seeding, >= 0.")
      .validator([](const GPOptions& o) { validate(o); })
      .finish();

  py::class_<FitInfo>(m, "FitInfo", "How a fit went (a snapshot, taken when fit_info is read).")
      .def_readonly("iterations", &FitInfo::iterations,
                    "iterations : int\n    L-BFGS-B iterations (0 without optimisation).")
      .def_readonly("evaluations", &FitInfo::evaluations,
                    "evaluations : int\n    Objective + gradient evaluations.")
      .def_readonly("log_marginal_likelihood", &FitInfo::log_marginal_likelihood,
                    "log_marginal_likelihood : float\n    At the fitted hyper-parameters (standardised outputs).")
      .def_readonly("jitter_used", &FitInfo::jitter_used,
                    "jitter_used : float\n    Final relative jitter that made the Cholesky factorisation succeed.")
      .def_readonly("message", &FitInfo::message,
                    "message : str\n    'converged', 'stopped: <reason>', or empty without optimisation.")
      .def("__repr__", [](const FitInfo& f) {
        return "FitInfo(iterations=" + std::to_string(f.iterations) + ", evaluations=" +
               std::to_string(f.evaluations) + ", log_marginal_likelihood=" +
               py::repr(py::float_(f.log_marginal_likelihood)).cast<std::string>() + ", message='" + f.message + "')";
      });
}

void bind_prediction(py::class_<GaussianProcess>& c) {
  c.def(
       "predict_mean",
       [](const GaussianProcess& gp, const DArray& X) {
         const Eigen::MatrixXd Xm = inputs(X);
         py::gil_scoped_release nogil;
         return gp.predict_mean(Xm);
       },
       "X"_a, "Predictive mean (N, P) at the rows of X (N, D).")
      .def(
          "predict",
          [](const GaussianProcess& gp, const DArray& X, bool include_noise) {
            const Eigen::MatrixXd Xm = inputs(X);
            Eigen::MatrixXd mean, var;
            {
              py::gil_scoped_release nogil;
              gp.predict(Xm, mean, var, predictive(include_noise));
            }
            return py::make_tuple(mean, var);
          },
          "X"_a, "include_noise"_a = false,
          "Predictive mean and variance, each (N, P); variance of f plus the noise if include_noise.")
      .def(
          "predict_cov",
          [](const GaussianProcess& gp, const DArray& X, int output, bool include_noise) {
            const Eigen::MatrixXd Xm = inputs(X);
            py::gil_scoped_release nogil;
            return gp.predict_cov(Xm, output, predictive(include_noise));
          },
          "X"_a, "output"_a = 0, "include_noise"_a = false,
          "Predictive covariance (N, N) of one output at the rows of X.")
      .def(
          "log_predictive_density",
          [](const GaussianProcess& gp, const DArray& X, const DArray& Y) {
            const Eigen::MatrixXd Xm = inputs(X);
            const Eigen::MatrixXd Ym = outputs(Y, "Y");
            py::gil_scoped_release nogil;
            return gp.log_predictive_density(Xm, Ym);
          },
          "X"_a, "Y"_a, "log p(Y_i | X_i) (N,): sum over outputs of log N(Y_ip | mean_ip, var_ip + noise_p).")
      .def(
          "sample",
          [](const GaussianProcess& gp, const DArray& X, int n_samples, std::uint64_t seed, bool include_noise,
             bool joint) {
            const Eigen::MatrixXd Xm = inputs(X);
            std::vector<Eigen::MatrixXd> s;
            {
              py::gil_scoped_release nogil;
              std::mt19937_64 rng(seed);
              s = joint ? gp.sample_joint(Xm, n_samples, rng, predictive(include_noise))
                        : gp.sample(Xm, n_samples, rng, predictive(include_noise));
            }
            return stack(s);
          },
          "X"_a, "n_samples"_a = 1, "seed"_a = 0, "include_noise"_a = true, "joint"_a = false,
          "Draws (n_samples, N, P) from the predictive distribution (std::mt19937_64 seeded with seed); "
          "marginal per input unless joint.");
}

}  // namespace

void bind_gp(py::module_& m) {
  bind_options(m);
  py::class_<GaussianProcess> gp(m, "GaussianProcess",
                                 "Common interface of ExactGP and SparseGP. Rows of X are inputs, rows of Y "
                                 "output vectors; hyper-parameters live in the standardised space.");
  gp.def(
        "fit",
        [](GaussianProcess& g, const DArray& X, const DArray& y) {
          const Eigen::MatrixXd Xm = cm(matrix(X, "X"));
          const Eigen::MatrixXd Ym = outputs(y, "y");
          py::gil_scoped_release nogil;
          g.fit(Xm, Ym);
        },
        "X"_a, "y"_a, "Fits to X (N, D) and y (N,) or (N, P); optimises the hyper-parameters if optimize.")
      .def_property_readonly("fitted", &GaussianProcess::fitted)
      .def_property_readonly("input_dim", &GaussianProcess::input_dim)
      .def_property_readonly("output_dim", &GaussianProcess::output_dim);
  bind_prediction(gp);
  gp.def("log_marginal_likelihood", &GaussianProcess::log_marginal_likelihood,
         "Log marginal likelihood of the fitted model (standardised outputs).")
      .def("parameters", &GaussianProcess::parameters,
           "Packed parameters [log lengthscales, log variance, log noise, mean constants, inducing inputs].")
      .def(
          "objective",
          [](const GaussianProcess& g, const DArray& theta) {
            const Eigen::VectorXd t = vector(theta, "theta");
            if (g.fitted() && t.size() != g.parameters().size())
              throw py::value_error("theta: expected " + std::to_string(g.parameters().size()) + " values");
            Eigen::VectorXd grad;
            double f;
            {
              py::gil_scoped_release nogil;
              f = g.objective(t, grad);
            }
            return py::make_tuple(f, grad);
          },
          "theta"_a, "Negative log marginal likelihood at theta and its analytic gradient.")
      .def_property_readonly("lengthscale", [](const GaussianProcess& g) { return g.kernel().lengthscale(); })
      .def_property_readonly("variance", [](const GaussianProcess& g) { return g.kernel().variance(); })
      .def_property_readonly("noise", &GaussianProcess::noise)
      .def_property_readonly("mean_constant", &GaussianProcess::mean_constant)
      .def_property_readonly("x_mean", &GaussianProcess::x_mean)
      .def_property_readonly("x_scale", &GaussianProcess::x_scale)
      .def_property_readonly("y_mean", &GaussianProcess::y_mean)
      .def_property_readonly("y_scale", &GaussianProcess::y_scale)
      .def_property_readonly("options", [](const GaussianProcess& g) { return g.options(); },
                             "The GPOptions the model was built with (a copy).")
      .def_property_readonly("fit_info", [](const GaussianProcess& g) { return g.fit_info(); },
                             "FitInfo of the last fit (a copy).")
      .def_property_readonly("threads", &GaussianProcess::threads,
                             "Threads of large prediction batches (options.threads by the one thread rule).")
      .def("set_threads", &GaussianProcess::set_threads, "threads"_a,
           "OpenMP threads for prediction batches of >= 2048 inputs (0 = all cores).");

  py::class_<ExactGP, GaussianProcess>(m, "ExactGP", "Exact GP regression (Cholesky of K + noise I).")
      .def(py::init<GPOptions>(), "options"_a = GPOptions{}, "A model with these options (checked here).");

  py::class_<SparseGP, GaussianProcess>(m, "SparseGP", "Sparse GP regression, FITC approximation.")
      .def(py::init<GPOptions>(), "options"_a = GPOptions{}, "A model with these options (checked here).")
      .def_property_readonly("inducing_inputs", &SparseGP::inducing_inputs, "Inducing inputs (M, D), input units.")
      .def_property_readonly("n_inducing", &SparseGP::n_inducing);
}

}  // namespace bayesgrasp::bind

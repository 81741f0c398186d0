// Bindings for the gp concept: ExactGP, SparseGP (FITC). Thin: validate, convert, release the
// GIL, call C++. The scikit-learn-style estimators live in python/bayesgrasp/gp.py.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <random>

#include "bayesgrasp/gp/gp.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace py = pybind11;
using namespace bayesgrasp::gp;

namespace {

Eigen::MatrixXd cm(const RowMatrixXd& m) { return m; }

/// y may be 1-D (N,) or 2-D (N, P).
Eigen::MatrixXd outputs(const DArray& y, const char* name, py::ssize_t rows) {
  if (y.ndim() == 1) {
    Eigen::VectorXd v = vector(y, name, rows);
    return v;
  }
  RowMatrixXd m = matrix(y, name);
  if (m.rows() != rows)
    throw py::value_error(std::string(name) + ": expected " + std::to_string(rows) + " rows, got " +
                          std::to_string(m.rows()));
  return m;
}

GPOptions make_options(const std::string& kernel, const py::object& lengthscale, double variance, double noise,
                       const std::string& mean, bool optimize, int max_iter, bool normalize_x, bool normalize_y,
                       double jitter, int threads, const py::object& mean_constant) {
  GPOptions o;
  if (!mean_constant.is_none()) {
    DArray a = py::cast<DArray>(mean_constant);
    o.mean_constant = a.ndim() == 0 ? Eigen::VectorXd::Constant(1, *a.data()) : vector(a, "mean_constant");
  }
  try {
    o.kernel = kernel_type_from_string(kernel);
    o.mean = mean_type_from_string(mean);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
  if (!lengthscale.is_none()) {
    DArray a = py::cast<DArray>(lengthscale);
    if (a.ndim() == 0) {
      o.lengthscale = Eigen::VectorXd::Constant(1, *a.data());
    } else {
      o.lengthscale = vector(a, "lengthscale");
    }
    if (o.lengthscale.size() == 0 || !(o.lengthscale.array() > 0).all())
      throw py::value_error("lengthscale: must be positive");
  }
  o.variance = positive(variance, "variance");
  if (!(noise >= 0.0) || !std::isfinite(noise)) throw py::value_error("noise: must be >= 0 and finite");
  o.noise = noise;
  o.optimize = optimize;
  if (max_iter < 0) throw py::value_error("max_iter: must be >= 0");
  o.max_iter = max_iter;
  o.normalize_x = normalize_x;
  o.normalize_y = normalize_y;
  if (!(jitter >= 0.0) || !std::isfinite(jitter)) throw py::value_error("jitter: must be >= 0");
  o.jitter = jitter;
  if (threads < 1) throw py::value_error("threads: must be >= 1");
  o.threads = threads;
  return o;
}

void require_fitted(const GaussianProcess& gp) {
  if (!gp.fitted()) throw py::value_error("the model is not fitted; call fit(X, y) first");
}

RowMatrixXd inputs(const GaussianProcess& gp, const DArray& X, const char* name = "X") {
  require_fitted(gp);
  return matrix(X, name, gp.input_dim(), true);
}

py::array_t<double> stack(const std::vector<Eigen::MatrixXd>& s) {
  const py::ssize_t S = s.size(), N = S ? s[0].rows() : 0, P = S ? s[0].cols() : 0;
  py::array_t<double> out({S, N, P});
  auto r = out.mutable_unchecked<3>();
  for (py::ssize_t k = 0; k < S; ++k)
    for (py::ssize_t i = 0; i < N; ++i)
      for (py::ssize_t p = 0; p < P; ++p) r(k, i, p) = s[k](i, p);
  return out;
}

}  // namespace

void bind_gp(py::module_& m) {
  py::class_<GaussianProcess>(m, "GaussianProcess",
                              "Common interface of ExactGP and SparseGP. Rows of X are inputs, rows of Y "
                              "output vectors; hyper-parameters live in the standardised space.")
      .def(
          "fit",
          [](GaussianProcess& gp, const DArray& X, const DArray& y) {
            const Eigen::MatrixXd Xm = cm(matrix(X, "X"));
            const Eigen::MatrixXd Ym = outputs(y, "y", Xm.rows());
            py::gil_scoped_release nogil;
            gp.fit(Xm, Ym);
          },
          py::arg("X"), py::arg("y"),
          "Fits to X (N, D) and y (N,) or (N, P); optimises the hyper-parameters if optimize.")
      .def_property_readonly("fitted", &GaussianProcess::fitted)
      .def_property_readonly("input_dim", &GaussianProcess::input_dim)
      .def_property_readonly("output_dim", &GaussianProcess::output_dim)
      .def(
          "predict_mean",
          [](const GaussianProcess& gp, const DArray& X) {
            const Eigen::MatrixXd Xm = cm(inputs(gp, X));
            Eigen::MatrixXd out;
            {
              py::gil_scoped_release nogil;
              out = gp.predict_mean(Xm);
            }
            return out;
          },
          py::arg("X"), "Predictive mean (N, P) at the rows of X (N, D).")
      .def(
          "predict",
          [](const GaussianProcess& gp, const DArray& X, bool include_noise) {
            const Eigen::MatrixXd Xm = cm(inputs(gp, X));
            Eigen::MatrixXd mean, var;
            {
              py::gil_scoped_release nogil;
              gp.predict(Xm, mean, var, include_noise);
            }
            return py::make_tuple(mean, var);
          },
          py::arg("X"), py::arg("include_noise") = false,
          "Predictive mean and variance, each (N, P); variance of f plus the noise if include_noise.")
      .def(
          "predict_cov",
          [](const GaussianProcess& gp, const DArray& X, int output, bool include_noise) {
            const Eigen::MatrixXd Xm = cm(inputs(gp, X));
            if (output < 0 || output >= gp.output_dim()) throw py::value_error("output: out of range");
            py::gil_scoped_release nogil;
            return gp.predict_cov(Xm, output, include_noise);
          },
          py::arg("X"), py::arg("output") = 0, py::arg("include_noise") = false,
          "Predictive covariance (N, N) of one output at the rows of X.")
      .def(
          "log_predictive_density",
          [](const GaussianProcess& gp, const DArray& X, const DArray& Y) {
            const Eigen::MatrixXd Xm = cm(inputs(gp, X));
            const Eigen::MatrixXd Ym = outputs(Y, "Y", Xm.rows());
            if (Ym.cols() != gp.output_dim())
              throw py::value_error("Y: expected " + std::to_string(gp.output_dim()) + " outputs, got " +
                                    std::to_string(Ym.cols()));
            py::gil_scoped_release nogil;
            return gp.log_predictive_density(Xm, Ym);
          },
          py::arg("X"), py::arg("Y"),
          "log p(Y_i | X_i) (N,): sum over outputs of log N(Y_ip | mean_ip, var_ip + noise_p).")
      .def(
          "sample",
          [](const GaussianProcess& gp, const DArray& X, int n_samples, std::uint64_t seed, bool include_noise,
             bool joint) {
            const Eigen::MatrixXd Xm = cm(inputs(gp, X));
            if (n_samples < 1) throw py::value_error("n_samples: must be >= 1");
            std::vector<Eigen::MatrixXd> s;
            {
              py::gil_scoped_release nogil;
              std::mt19937_64 rng(seed);
              s = joint ? gp.sample_joint(Xm, n_samples, rng, include_noise)
                        : gp.sample(Xm, n_samples, rng, include_noise);
            }
            return stack(s);
          },
          py::arg("X"), py::arg("n_samples") = 1, py::arg("seed") = 0, py::arg("include_noise") = true,
          py::arg("joint") = false,
          "Draws (n_samples, N, P) from the predictive distribution (std::mt19937_64 seeded with seed); "
          "marginal per input unless joint.")
      .def("log_marginal_likelihood", &GaussianProcess::log_marginal_likelihood,
           "Log marginal likelihood of the fitted model (standardised outputs).")
      .def("parameters", &GaussianProcess::parameters,
           "Packed parameters [log lengthscales, log variance, log noise, mean constants, inducing inputs].")
      .def(
          "objective",
          [](const GaussianProcess& gp, const DArray& theta) {
            require_fitted(gp);
            const Eigen::VectorXd t = vector(theta, "theta");
            if (t.size() != gp.parameters().size())
              throw py::value_error("theta: expected " + std::to_string(gp.parameters().size()) + " values");
            Eigen::VectorXd g;
            double f;
            {
              py::gil_scoped_release nogil;
              f = gp.objective(t, g);
            }
            return py::make_tuple(f, g);
          },
          py::arg("theta"), "Negative log marginal likelihood at theta and its analytic gradient.")
      .def_property_readonly("lengthscale", [](const GaussianProcess& gp) { return gp.kernel().lengthscale(); })
      .def_property_readonly("variance", [](const GaussianProcess& gp) { return gp.kernel().variance(); })
      .def_property_readonly("noise", &GaussianProcess::noise)
      .def_property_readonly("mean_constant", &GaussianProcess::mean_constant)
      .def_property_readonly("x_mean", &GaussianProcess::x_mean)
      .def_property_readonly("x_scale", &GaussianProcess::x_scale)
      .def_property_readonly("y_mean", &GaussianProcess::y_mean)
      .def_property_readonly("y_scale", &GaussianProcess::y_scale)
      .def_property_readonly("fit_info",
                             [](const GaussianProcess& gp) {
                               const FitInfo& f = gp.fit_info();
                               py::dict d;
                               d["iterations"] = f.iterations;
                               d["evaluations"] = f.evaluations;
                               d["log_marginal_likelihood"] = f.log_marginal_likelihood;
                               d["jitter_used"] = f.jitter_used;
                               d["message"] = f.message;
                               return d;
                             })
      .def("set_threads", &GaussianProcess::set_threads, py::arg("threads"),
           "OpenMP threads for prediction batches of >= 2048 inputs.");

  py::class_<ExactGP, GaussianProcess>(m, "ExactGP", "Exact GP regression (Cholesky of K + noise I).")
      .def(py::init([](const std::string& kernel, const py::object& lengthscale, double variance, double noise,
                       const std::string& mean, bool optimize, int max_iter, bool normalize_x, bool normalize_y,
                       double jitter, int threads, const py::object& mean_constant) {
             return std::make_unique<ExactGP>(make_options(kernel, lengthscale, variance, noise, mean, optimize,
                                                           max_iter, normalize_x, normalize_y, jitter, threads,
                                                           mean_constant));
           }),
           py::arg("kernel") = "se", py::arg("lengthscale") = py::none(), py::arg("variance") = 1.0,
           py::arg("noise") = 1e-2, py::arg("mean") = "zero", py::arg("optimize") = true, py::arg("max_iter") = 200,
           py::arg("normalize_x") = true, py::arg("normalize_y") = true, py::arg("jitter") = 1e-8,
           py::arg("threads") = 1, py::arg("mean_constant") = py::none(),
           "kernel: 'se' | 'matern52'; lengthscale: scalar or (D,) (None = 1); variance, noise: initial "
           "values; mean: 'zero' | 'constant'; mean_constant: initial constants (P,) (None = automatic).");

  py::class_<SparseGP, GaussianProcess>(m, "SparseGP", "Sparse GP regression, FITC approximation.")
      .def(py::init([](const std::string& kernel, const py::object& lengthscale, double variance, double noise,
                       const std::string& mean, bool optimize, int max_iter, bool normalize_x, bool normalize_y,
                       double jitter, int threads, int n_inducing, bool optimize_inducing, std::uint64_t seed,
                       const py::object& inducing, int kmeans_iter, const py::object& mean_constant) {
             GPOptions o = make_options(kernel, lengthscale, variance, noise, mean, optimize, max_iter, normalize_x,
                                        normalize_y, jitter, threads, mean_constant);
             if (n_inducing < 1) throw py::value_error("n_inducing: must be >= 1");
             o.n_inducing = n_inducing;
             o.optimize_inducing = optimize_inducing;
             o.seed = seed;
             if (kmeans_iter < 0) throw py::value_error("kmeans_iter: must be >= 0");
             o.kmeans_iter = kmeans_iter;
             if (!inducing.is_none()) o.inducing = cm(matrix(py::cast<DArray>(inducing), "inducing"));
             return std::make_unique<SparseGP>(o);
           }),
           py::arg("kernel") = "se", py::arg("lengthscale") = py::none(), py::arg("variance") = 1.0,
           py::arg("noise") = 1e-2, py::arg("mean") = "zero", py::arg("optimize") = true, py::arg("max_iter") = 200,
           py::arg("normalize_x") = true, py::arg("normalize_y") = true, py::arg("jitter") = 1e-8,
           py::arg("threads") = 1, py::arg("n_inducing") = 200, py::arg("optimize_inducing") = false,
           py::arg("seed") = 0, py::arg("inducing") = py::none(), py::arg("kmeans_iter") = 10,
           py::arg("mean_constant") = py::none(),
           "As ExactGP, plus n_inducing (M), optimize_inducing, seed (k-means++), inducing: fixed initial "
           "inducing inputs (M, D) in input units (None = k-means++).")
      .def_property_readonly("inducing_inputs", &SparseGP::inducing_inputs, "Inducing inputs (M, D), input units.")
      .def_property_readonly("n_inducing", &SparseGP::n_inducing);
}

}  // namespace bayesgrasp::bind

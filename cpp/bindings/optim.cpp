// Bindings for the optim concept: PSO, simulated annealing, firefly, steepest descent,
// Levenberg-Marquardt and a dogleg trust region. Thin: validate, convert, release the GIL and
// re-acquire it only around calls of a Python objective. The common result object lives in
// python/bayesgrasp/optim.py.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <limits>

#include "bayesgrasp/optim/annealing.hpp"
#include "bayesgrasp/optim/firefly.hpp"
#include "bayesgrasp/optim/pso.hpp"
#include "bayesgrasp/optim/trust_region.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace py = pybind11;
using namespace py::literals;
namespace op = bayesgrasp::optim;

namespace {

constexpr double kNegInf = -std::numeric_limits<double>::infinity();

/// A C++ built-in (by name) or a vectorised Python callable (N, D) -> (N,), called with the GIL.
op::BatchObjective objective_from(const py::object& obj) {
  if (py::isinstance<py::str>(obj)) {
    try {
      return op::builtin_objective(obj.cast<std::string>());
    } catch (const std::invalid_argument& e) {
      throw py::value_error(e.what());
    }
  }
  if (!PyCallable_Check(obj.ptr()))
    throw py::value_error("objective: expected a callable (N, D) -> (N,) or a built-in name");
  py::function fn = py::reinterpret_borrow<py::function>(obj);
  return [fn](const op::RowMatrixXd& X, Eigen::VectorXd& f) {
    py::gil_scoped_acquire gil;
    py::array_t<double> arr({X.rows(), X.cols()});
    std::copy(X.data(), X.data() + X.size(), arr.mutable_data());
    py::object out = fn(arr);
    DArray a = py::cast<DArray>(out);
    if (!(a.ndim() == 1 || (a.ndim() == 2 && a.shape(1) == 1)) || a.shape(0) != X.rows())
      throw py::value_error("objective: must return an array of shape (" + std::to_string(X.rows()) +
                            ",), got " + shape_str(a));
    std::copy(a.data(), a.data() + X.rows(), f.data());
  };
}

/// Vectorised Python residuals (N, D) -> (N, R).
op::BatchResiduals residuals_from(const py::object& obj) {
  if (!PyCallable_Check(obj.ptr())) throw py::value_error("residuals: expected a callable (N, D) -> (N, R)");
  py::function fn = py::reinterpret_borrow<py::function>(obj);
  return [fn](const op::RowMatrixXd& X, op::RowMatrixXd& R) {
    py::gil_scoped_acquire gil;
    py::array_t<double> arr({X.rows(), X.cols()});
    std::copy(X.data(), X.data() + X.size(), arr.mutable_data());
    DArray a = py::cast<DArray>(fn(arr));
    if (a.ndim() == 1 && X.rows() == 1) {
      R = Eigen::Map<const op::RowMatrixXd>(a.data(), 1, a.shape(0));
      return;
    }
    if (a.ndim() != 2 || a.shape(0) != X.rows())
      throw py::value_error("residuals: must return an array of shape (" + std::to_string(X.rows()) + ", R), got " +
                            shape_str(a));
    R = Eigen::Map<const op::RowMatrixXd>(a.data(), a.shape(0), a.shape(1));
  };
}

op::Bounds bounds_from(const DArray& low, const DArray& high) {
  op::Bounds b{vector(low, "low"), vector(high, "high")};
  if (b.low.size() == 0) throw py::value_error("low: must have at least one entry");
  if (b.high.size() != b.low.size()) throw py::value_error("high: expected the same length as low");
  for (int i = 0; i < b.dim(); ++i)
    if (b.low[i] > b.high[i])
      throw py::value_error("bounds: low > high in dimension " + std::to_string(i) + " (" + std::to_string(b.low[i]) +
                            " > " + std::to_string(b.high[i]) + ")");
  return b;
}

op::Bounds optional_bounds(const py::object& low, const py::object& high, Eigen::Index dim) {
  if (low.is_none() && high.is_none()) return {};
  if (low.is_none() || high.is_none()) throw py::value_error("bounds: give both low and high, or neither");
  op::Bounds b = bounds_from(py::cast<DArray>(low), py::cast<DArray>(high));
  if (b.dim() != dim) throw py::value_error("low: expected the same length as x0");
  return b;
}

op::RowMatrixXd optional_init(const py::object& init, int n, int d) {
  if (init.is_none()) return {};
  op::RowMatrixXd m = matrix(py::cast<DArray>(init), "init", d);
  if (m.rows() != n) throw py::value_error("init: expected " + std::to_string(n) + " rows");
  return m;
}

py::dict to_dict(const op::Result& r) {
  return py::dict("x"_a = r.x, "fun"_a = r.f, "nit"_a = r.iterations, "nfev"_a = r.evaluations,
                  "history"_a = r.history, "converged"_a = r.converged, "message"_a = r.message);
}

/// Runs f without the GIL, mapping std::invalid_argument to ValueError.
template <class F>
op::Result run(F&& f) {
  try {
    py::gil_scoped_release release;
    return f();
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

}  // namespace

void bind_optim(py::module_& m) {
  m.def(
      "pso",
      [](const py::object& objective, const DArray& low, const DArray& high, int n_particles, int max_iter,
         double inertia, double c1, double c2, double vmax_fraction, std::uint64_t seed, double target,
         int stall_iter, double ftol, const py::object& init, bool record_history) {
        const op::Bounds b = bounds_from(low, high);
        op::PSOOptions o;
        o.n_particles = n_particles;
        o.max_iter = max_iter;
        o.inertia = finite(inertia, "inertia");
        o.c1 = finite(c1, "c1");
        o.c2 = finite(c2, "c2");
        o.vmax_fraction = positive(vmax_fraction, "vmax_fraction");
        o.seed = seed;
        o.target = target;
        o.stall_iter = stall_iter;
        o.ftol = ftol;
        o.init = optional_init(init, n_particles, b.dim());
        o.record_history = record_history;
        const op::BatchObjective fun = objective_from(objective);
        return to_dict(run([&] { return op::pso(fun, b, o); }));
      },
      "objective"_a, "low"_a, "high"_a, "n_particles"_a = 40, "max_iter"_a = 200, "inertia"_a = 0.7298,
      "c1"_a = 1.49618, "c2"_a = 1.49618, "vmax_fraction"_a = 0.5, "seed"_a = 0, "target"_a = kNegInf,
      "stall_iter"_a = 0, "ftol"_a = 0.0, "init"_a = py::none(), "record_history"_a = false,
      "Particle swarm optimisation (global best, constriction parameters) of objective over the box\n"
      "[low, high]. objective: a vectorised callable (N, D) -> (N,) called once per iteration with the\n"
      "whole swarm, or a built-in name ('sphere', 'rastrigin', 'ackley', 'rosenbrock'). Returns a dict\n"
      "(x, fun, nit, nfev, history, converged, message).");

  m.def(
      "simulated_annealing",
      [](const py::object& objective, const DArray& low, const DArray& high, int n_chains, int max_iter, double t0,
         double cooling, double step, double step_min, double step_max, int adapt_interval,
         double target_acceptance, double adapt_factor, std::uint64_t seed, double target, const py::object& init,
         bool record_history) {
        const op::Bounds b = bounds_from(low, high);
        op::AnnealingOptions o;
        o.n_chains = n_chains;
        o.max_iter = max_iter;
        o.t0 = t0;
        o.cooling = cooling;
        o.step = step;
        o.step_min = step_min;
        o.step_max = step_max;
        o.adapt_interval = adapt_interval;
        o.target_acceptance = target_acceptance;
        o.adapt_factor = adapt_factor;
        o.seed = seed;
        o.target = target;
        o.init = optional_init(init, n_chains, b.dim());
        o.record_history = record_history;
        const op::BatchObjective fun = objective_from(objective);
        return to_dict(run([&] { return op::simulated_annealing(fun, b, o); }));
      },
      "objective"_a, "low"_a, "high"_a, "n_chains"_a = 16, "max_iter"_a = 1000, "t0"_a = -1.0, "cooling"_a = 0.98,
      "step"_a = 0.1, "step_min"_a = 1e-9, "step_max"_a = 0.5, "adapt_interval"_a = 10,
      "target_acceptance"_a = 0.2, "adapt_factor"_a = 1.5, "seed"_a = 0, "target"_a = kNegInf,
      "init"_a = py::none(), "record_history"_a = false,
      "Simulated annealing with n_chains Metropolis chains evaluated as one batch per iteration, bounded\n"
      "(reflected) Gaussian proposals with per-chain adaptive step (fraction of the range), geometric\n"
      "cooling T_k = t0 cooling^k (t0 <= 0: std of f over the initial points). Returns a dict.");

  m.def(
      "firefly",
      [](const py::object& objective, const DArray& low, const DArray& high, int n_fireflies, int max_iter,
         double beta0, double gamma, double alpha, double alpha_decay, std::uint64_t seed, double target,
         const py::object& init, bool record_history) {
        const op::Bounds b = bounds_from(low, high);
        op::FireflyOptions o;
        o.n_fireflies = n_fireflies;
        o.max_iter = max_iter;
        o.beta0 = beta0;
        o.gamma = gamma;
        o.alpha = alpha;
        o.alpha_decay = alpha_decay;
        o.seed = seed;
        o.target = target;
        o.init = optional_init(init, n_fireflies, b.dim());
        o.record_history = record_history;
        const op::BatchObjective fun = objective_from(objective);
        return to_dict(run([&] { return op::firefly(fun, b, o); }));
      },
      "objective"_a, "low"_a, "high"_a, "n_fireflies"_a = 25, "max_iter"_a = 100, "beta0"_a = 1.0, "gamma"_a = 1.0,
      "alpha"_a = 0.2, "alpha_decay"_a = 0.97, "seed"_a = 0, "target"_a = kNegInf, "init"_a = py::none(),
      "record_history"_a = false,
      "The firefly algorithm (Yang 2008): attractiveness beta0 exp(-gamma r^2), random step alpha (u - 1/2)\n"
      "decaying by alpha_decay per generation; distances and steps in unit-box coordinates. Returns a dict.");

  m.def(
      "steepest_descent",
      [](const py::object& objective, const DArray& x0, const py::object& low, const py::object& high, int max_iter,
         double h, double t0, double armijo, double backtrack, int max_backtrack, double gtol, double ftol,
         bool record_history) {
        const Eigen::VectorXd x = vector(x0, "x0");
        const op::Bounds b = optional_bounds(low, high, x.size());
        op::DescentOptions o;
        o.max_iter = max_iter;
        o.h = h;
        o.t0 = t0;
        o.armijo = armijo;
        o.backtrack = backtrack;
        o.max_backtrack = max_backtrack;
        o.gtol = gtol;
        o.ftol = ftol;
        o.record_history = record_history;
        const op::BatchObjective fun = objective_from(objective);
        return to_dict(run([&] { return op::steepest_descent(fun, x, b, o); }));
      },
      "objective"_a, "x0"_a, "low"_a = py::none(), "high"_a = py::none(), "max_iter"_a = 500, "h"_a = 1e-6,
      "t0"_a = 1.0, "armijo"_a = 1e-4, "backtrack"_a = 0.5, "max_backtrack"_a = 40, "gtol"_a = 1e-8,
      "ftol"_a = 1e-14, "record_history"_a = false,
      "Steepest descent from x0 with central-difference gradients (one batch of 2D rows) and an Armijo\n"
      "backtracking line search; projected onto [low, high] if given. Returns a dict.");

  m.def(
      "levenberg_marquardt",
      [](const py::object& residuals, const DArray& x0, const py::object& low, const py::object& high, int max_iter,
         double h, double lambda0, double gtol, double xtol, double ftol, bool record_history) {
        const Eigen::VectorXd x = vector(x0, "x0");
        const op::Bounds b = optional_bounds(low, high, x.size());
        op::LMOptions o;
        o.max_iter = max_iter;
        o.h = h;
        o.lambda0 = lambda0;
        o.gtol = gtol;
        o.xtol = xtol;
        o.ftol = ftol;
        o.record_history = record_history;
        const op::BatchResiduals fun = residuals_from(residuals);
        return to_dict(run([&] { return op::levenberg_marquardt(fun, x, b, o); }));
      },
      "residuals"_a, "x0"_a, "low"_a = py::none(), "high"_a = py::none(), "max_iter"_a = 200, "h"_a = 1e-6,
      "lambda0"_a = 1e-3, "gtol"_a = 1e-10, "xtol"_a = 1e-12, "ftol"_a = 1e-15, "record_history"_a = false,
      "Levenberg-Marquardt on f(x) = 1/2 |r(x)|^2; residuals: vectorised callable (N, D) -> (N, R); the\n"
      "Jacobian by central differences in one batch. Returns a dict (fun = 1/2 |r|^2).");

  m.def(
      "trust_region",
      [](const py::object& objective, const DArray& x0, const py::object& low, const py::object& high, int max_iter,
         double h, double radius0, double max_radius, double eta, double gtol, double xtol, bool record_history) {
        const Eigen::VectorXd x = vector(x0, "x0");
        const op::Bounds b = optional_bounds(low, high, x.size());
        op::TrustRegionOptions o;
        o.max_iter = max_iter;
        o.h = h;
        o.radius0 = radius0;
        o.max_radius = max_radius;
        o.eta = eta;
        o.gtol = gtol;
        o.xtol = xtol;
        o.record_history = record_history;
        const op::BatchObjective fun = objective_from(objective);
        return to_dict(run([&] { return op::trust_region(fun, x, b, o); }));
      },
      "objective"_a, "x0"_a, "low"_a = py::none(), "high"_a = py::none(), "max_iter"_a = 200, "h"_a = 1e-6,
      "radius0"_a = 1.0, "max_radius"_a = 1e6, "eta"_a = 1e-4, "gtol"_a = 1e-8, "xtol"_a = 1e-12,
      "record_history"_a = false,
      "Dogleg trust region with central-difference gradients and BFGS Hessian updates on a scalar\n"
      "objective (e.g. the negative log posterior of a pose, Eq. 4.4). Returns a dict.");

  m.def(
      "evaluate_builtin",
      [](const std::string& name, const DArray& X) {
        op::BatchObjective f;
        try {
          f = op::builtin_objective(name);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
        const op::RowMatrixXd x = matrix(X, "X");
        Eigen::VectorXd v(x.rows());
        f(x, v);
        return v;
      },
      "name"_a, "X"_a, "Evaluates a built-in test function at the rows of X (N, D); returns (N,).");
}

}  // namespace bayesgrasp::bind

// Bindings for the optim concept: PSO, simulated annealing, firefly, steepest descent,
// Levenberg-Marquardt and a dogleg trust region, each taking its options class and returning an
// OptimizeResult. Thin: convert, release the GIL and re-acquire it only around calls of a Python
// objective; the core validates (its std::invalid_argument becomes ValueError).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bayesgrasp/optim/annealing.hpp"
#include "bayesgrasp/optim/firefly.hpp"
#include "bayesgrasp/optim/pso.hpp"
#include "bayesgrasp/optim/trust_region.hpp"
#include "options.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace py = pybind11;
using namespace py::literals;
namespace op = bayesgrasp::optim;

namespace {

/// What every optimiser returns to Python: op::Result with numpy arrays (owned, writable).
struct OptimizeResult {
  py::array_t<double> x, history;
  double fun = 0.0;
  int nit = 0;
  long long nfev = 0;
  bool converged = false;
  std::string message;
};

OptimizeResult to_python(const op::Result& r) {
  OptimizeResult out;
  out.x = py::array_t<double>(r.x.size(), r.x.data());
  out.history = py::array_t<double>(static_cast<py::ssize_t>(r.history.size()), r.history.data());
  out.fun = r.f;
  out.nit = r.iterations;
  out.nfev = r.evaluations;
  out.converged = r.converged;
  out.message = r.message;
  return out;
}

/// Copies a batch of candidates into a new numpy array (the argument of a Python callback).
py::array_t<double> candidates(const op::RowMatrixXd& X) {
  py::array_t<double> arr({X.rows(), X.cols()});
  std::copy(X.data(), X.data() + X.size(), arr.mutable_data());
  return arr;
}

/// A C++ built-in (by name) or a vectorised Python callable (N, D) -> (N,), called with the GIL.
op::BatchObjective objective_from(const py::object& obj) {
  if (py::isinstance<py::str>(obj)) return op::builtin_objective(obj.cast<std::string>());
  if (!PyCallable_Check(obj.ptr()))
    throw py::value_error("objective: expected a callable (N, D) -> (N,) or a built-in name");
  py::function fn = py::reinterpret_borrow<py::function>(obj);
  return [fn](const op::RowMatrixXd& X, Eigen::VectorXd& f) {
    py::gil_scoped_acquire gil;
    DArray a = py::cast<DArray>(fn(candidates(X)));
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
    DArray a = py::cast<DArray>(fn(candidates(X)));
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

/// The box [low, high] (validated by the optimiser); both None = unconstrained.
op::Bounds bounds_from(const py::object& low, const py::object& high) {
  if (low.is_none() && high.is_none()) return {};
  if (low.is_none() || high.is_none()) throw py::value_error("bounds: give both low and high, or neither");
  return op::Bounds{vector(py::cast<DArray>(low), "low"), vector(py::cast<DArray>(high), "high")};
}

/// Runs an optimiser without the GIL.
template <class F>
OptimizeResult run(F&& f) {
  op::Result r;
  {
    py::gil_scoped_release release;
    r = f();
  }
  return to_python(r);
}

void bind_result(py::module_& m) {
  py::class_<OptimizeResult>(m, "OptimizeResult", "What every optimiser reports.")
      .def_readonly("x", &OptimizeResult::x, "x : numpy.ndarray\n    Best point found (D,).")
      .def_readonly("fun", &OptimizeResult::fun,
                    "fun : float\n    Objective at x (for levenberg_marquardt: 1/2 |r|^2).")
      .def_readonly("nit", &OptimizeResult::nit, "nit : int\n    Iterations done.")
      .def_readonly("nfev", &OptimizeResult::nfev,
                    "nfev : int\n    Rows passed to the objective (candidate evaluations).")
      .def_readonly("history", &OptimizeResult::history,
                    "history : numpy.ndarray\n    Best value after each iteration (empty unless record_history).")
      .def_readonly("converged", &OptimizeResult::converged,
                    "converged : bool\n    A tolerance or the target was met (else the budget ran out).")
      .def_readonly("message", &OptimizeResult::message, "message : str\n    Why it stopped.")
      .def("__repr__", [](const OptimizeResult& r) {
        return "OptimizeResult(x=" + py::repr(r.x).cast<std::string>() +
               ", fun=" + py::repr(py::float_(r.fun)).cast<std::string>() + ", nit=" + std::to_string(r.nit) +
               ", nfev=" + std::to_string(r.nfev) + ", converged=" + (r.converged ? "True" : "False") +
               ", message='" + r.message + "')";
      });
}

/// The fields every population optimiser's options share (op::PopulationOptions).
template <class Options>
void finish_population(OptionClass<Options>& c, const char* size_name) {
  c.field("seed", &Options::seed, "int", "Seed of the optimiser's generator.")
      .field("target", &Options::target, "float", "Stop once the best value is <= target.")
      .field("record_history", &Options::record_history, "bool", "Record the best value after each iteration.")
      .field("init", &Options::init, "numpy.ndarray",
             (std::string("Optional (") + size_name + ", D) starting points, clipped into the box; empty = uniform in "
                                                      "the box.").c_str())
      .validator([](const Options& o) { op::validate(o); })
      .finish();
}

void bind_global_options(py::module_& m) {
  OptionClass<op::PSOOptions> pso(m, "PSOOptions", "Options of pso (defaults: Clerc & Kennedy's constriction).");
  pso.field("n_particles", &op::PSOOptions::n_particles, "int", "Swarm size, >= 1.")
      .field("max_iter", &op::PSOOptions::max_iter, "int", "Swarm updates after the initial evaluation, >= 0.")
      .field("inertia", &op::PSOOptions::inertia, "float", "Velocity inertia weight.")
      .field("c1", &op::PSOOptions::c1, "float", "Cognitive (own best) weight.")
      .field("c2", &op::PSOOptions::c2, "float", "Social (swarm best) weight.")
      .field("vmax_fraction", &op::PSOOptions::vmax_fraction, "float",
             "Velocity bound as a fraction of the range, > 0.")
      .field("stall_iter", &op::PSOOptions::stall_iter, "int",
             "Stop after this many iterations improving by at most ftol (0: off).")
      .field("ftol", &op::PSOOptions::ftol, "float", "Improvement that resets the stall count.");
  finish_population(pso, "n_particles");

  OptionClass<op::AnnealingOptions> sa(m, "AnnealingOptions", "Options of simulated_annealing.");
  sa.field("n_chains", &op::AnnealingOptions::n_chains, "int", "Metropolis chains, >= 1.")
      .field("max_iter", &op::AnnealingOptions::max_iter, "int",
             "Proposals per chain after the initial evaluation, >= 0.")
      .field("t0", &op::AnnealingOptions::t0, "float",
             "Initial temperature; <= 0: the std of f over the initial points.")
      .field("cooling", &op::AnnealingOptions::cooling, "float",
             "Geometric cooling factor T_k = t0 cooling^k, in (0, 1].")
      .field("step", &op::AnnealingOptions::step, "float", "Initial proposal std as a fraction of the range, > 0.")
      .field("step_min", &op::AnnealingOptions::step_min, "float",
             "Lower bound of the adapted step (fraction of the range), > 0.")
      .field("step_max", &op::AnnealingOptions::step_max, "float", "Upper bound of the adapted step, >= step_min.")
      .field("adapt_interval", &op::AnnealingOptions::adapt_interval, "int",
             "Iterations between step adaptations (0 = fixed step).")
      .field("target_acceptance", &op::AnnealingOptions::target_acceptance, "float",
             "Acceptance rate the step adapts towards, in (0, 1).")
      .field("adapt_factor", &op::AnnealingOptions::adapt_factor, "float", "Step growth / shrink factor, > 1.");
  finish_population(sa, "n_chains");

  OptionClass<op::FireflyOptions> ff(m, "FireflyOptions", "Options of firefly (Yang 2008).");
  ff.field("n_fireflies", &op::FireflyOptions::n_fireflies, "int", "Population, >= 1.")
      .field("max_iter", &op::FireflyOptions::max_iter, "int", "Generations after the initial evaluation, >= 0.")
      .field("beta0", &op::FireflyOptions::beta0, "float", "Attractiveness at distance 0, >= 0.")
      .field("gamma", &op::FireflyOptions::gamma, "float", "Light absorption (unit-box coordinates), >= 0.")
      .field("alpha", &op::FireflyOptions::alpha, "float", "Initial random step (fraction of the range), >= 0.")
      .field("alpha_decay", &op::FireflyOptions::alpha_decay, "float", "alpha_k = alpha alpha_decay^k, in (0, 1].");
  finish_population(ff, "n_fireflies");
}

void bind_local_options(py::module_& m) {
  OptionClass<op::DescentOptions>(m, "DescentOptions", "Options of steepest_descent.")
      .field("max_iter", &op::DescentOptions::max_iter, "int", "Iterations, >= 0.")
      .field("h", &op::DescentOptions::h, "float", "Relative finite-difference step, > 0.")
      .field("t0", &op::DescentOptions::t0, "float", "First trial step length, > 0.")
      .field("armijo", &op::DescentOptions::armijo, "float", "Sufficient-decrease constant, in (0, 1).")
      .field("backtrack", &op::DescentOptions::backtrack, "float", "Step shrink factor, in (0, 1).")
      .field("max_backtrack", &op::DescentOptions::max_backtrack, "int", "Line-search trials per iteration.")
      .field("gtol", &op::DescentOptions::gtol, "float", "Stop when the projected gradient's max-norm is below gtol.")
      .field("ftol", &op::DescentOptions::ftol, "float", "Stop when the relative decrease is below ftol.")
      .field("record_history", &op::DescentOptions::record_history, "bool", "Record the value after each iteration.")
      .validator([](const op::DescentOptions& o) { op::validate(o); })
      .finish();

  OptionClass<op::LMOptions>(m, "LMOptions", "Options of levenberg_marquardt.")
      .field("max_iter", &op::LMOptions::max_iter, "int", "Iterations, >= 0.")
      .field("h", &op::LMOptions::h, "float", "Relative finite-difference step, > 0.")
      .field("lambda0", &op::LMOptions::lambda0, "float", "Initial damping relative to max diag(J^T J), > 0.")
      .field("gtol", &op::LMOptions::gtol, "float", "Stop when max |J^T r| < gtol.")
      .field("xtol", &op::LMOptions::xtol, "float", "Stop when |dx| < xtol (|x| + xtol).")
      .field("ftol", &op::LMOptions::ftol, "float", "Stop when 1/2 |r|^2 < ftol.")
      .field("record_history", &op::LMOptions::record_history, "bool", "Record the value after each iteration.")
      .validator([](const op::LMOptions& o) { op::validate(o); })
      .finish();

  OptionClass<op::TrustRegionOptions>(m, "TrustRegionOptions", "Options of trust_region.")
      .field("max_iter", &op::TrustRegionOptions::max_iter, "int", "Iterations, >= 0.")
      .field("h", &op::TrustRegionOptions::h, "float", "Relative finite-difference step, > 0.")
      .field("radius0", &op::TrustRegionOptions::radius0, "float", "Initial trust radius, > 0.")
      .field("max_radius", &op::TrustRegionOptions::max_radius, "float", "Largest trust radius.")
      .field("eta", &op::TrustRegionOptions::eta, "float",
             "Accept a step when actual / predicted reduction > eta, in [0, 0.25).")
      .field("gtol", &op::TrustRegionOptions::gtol, "float", "Stop when the gradient's max-norm < gtol.")
      .field("xtol", &op::TrustRegionOptions::xtol, "float", "Stop when the trust radius < xtol (|x| + xtol).")
      .field("record_history", &op::TrustRegionOptions::record_history, "bool",
             "Record the value after each iteration.")
      .validator([](const op::TrustRegionOptions& o) { op::validate(o); })
      .finish();
}

/// Binds a global optimiser f(objective, bounds, options) as name(objective, low, high, options).
template <class Options>
void def_global(py::module_& m, const char* name,
                op::Result (*f)(const op::BatchObjective&, const op::Bounds&, const Options&), const char* doc) {
  m.def(
      name,
      [f](const py::object& objective, const DArray& low, const DArray& high, const Options& o) {
        const op::Bounds b{vector(low, "low"), vector(high, "high")};
        const op::BatchObjective fun = objective_from(objective);
        return run([&] { return f(fun, b, o); });
      },
      "objective"_a, "low"_a, "high"_a, "options"_a = Options{}, doc);
}

/// Binds a local optimiser f(fun, x0, bounds, options) as name(fun, x0, low=None, high=None,
/// options); Fun is a batch objective or batch residuals, made from the Python callable by `make`.
template <class Fun, class Options>
void def_local(py::module_& m, const char* name, const char* fun_name, Fun (*make)(const py::object&),
               op::Result (*f)(const Fun&, const Eigen::VectorXd&, const op::Bounds&, const Options&),
               const char* doc) {
  m.def(
      name,
      [make, f](const py::object& objective, const DArray& x0, const py::object& low, const py::object& high,
                const Options& o) {
        const Eigen::VectorXd x = vector(x0, "x0");
        const op::Bounds b = bounds_from(low, high);
        const Fun fun = make(objective);
        return run([&] { return f(fun, x, b, o); });
      },
      py::arg(fun_name), "x0"_a, "low"_a = py::none(), "high"_a = py::none(), "options"_a = Options{}, doc);
}

void bind_optimisers(py::module_& m) {
  def_global<op::PSOOptions>(
      m, "pso", op::pso,
      "Particle swarm optimisation (global best, constriction parameters) of objective over the box\n"
      "[low, high]. objective: a vectorised callable (N, D) -> (N,) called once per iteration with the\n"
      "whole swarm, or a built-in name ('sphere', 'rastrigin', 'ackley', 'rosenbrock').");
  def_global<op::AnnealingOptions>(
      m, "simulated_annealing", op::simulated_annealing,
      "Simulated annealing with n_chains Metropolis chains evaluated as one batch per iteration, bounded\n"
      "(reflected) Gaussian proposals with per-chain adaptive step (fraction of the range), geometric\n"
      "cooling T_k = t0 cooling^k (t0 <= 0: std of f over the initial points).");
  def_global<op::FireflyOptions>(
      m, "firefly", op::firefly,
      "The firefly algorithm (Yang 2008): attractiveness beta0 exp(-gamma r^2), random step alpha (u - 1/2)\n"
      "decaying by alpha_decay per generation; distances and steps in unit-box coordinates.");
  def_local<op::BatchObjective, op::DescentOptions>(
      m, "steepest_descent", "objective", objective_from, op::steepest_descent,
      "Steepest descent from x0 with central-difference gradients (one batch of 2D rows) and an Armijo\n"
      "backtracking line search; projected onto [low, high] if given.");
  def_local<op::BatchResiduals, op::LMOptions>(
      m, "levenberg_marquardt", "residuals", residuals_from, op::levenberg_marquardt,
      "Levenberg-Marquardt on f(x) = 1/2 |r(x)|^2; residuals: vectorised callable (N, D) -> (N, R); the\n"
      "Jacobian by central differences in one batch (fun = 1/2 |r|^2).");
  def_local<op::BatchObjective, op::TrustRegionOptions>(
      m, "trust_region", "objective", objective_from, op::trust_region,
      "Dogleg trust region with central-difference gradients and BFGS Hessian updates on a scalar\n"
      "objective (e.g. the negative log posterior of a pose, Eq. 4.4).");
}

}  // namespace

void bind_optim(py::module_& m) {
  bind_result(m);
  bind_global_options(m);
  bind_local_options(m);
  bind_optimisers(m);
  m.def(
      "evaluate_builtin",
      [](const std::string& name, const DArray& X) {
        const op::BatchObjective f = op::builtin_objective(name);
        const op::RowMatrixXd x = matrix(X, "X");
        Eigen::VectorXd v(x.rows());
        f(x, v);
        return v;
      },
      "name"_a, "X"_a, "Evaluates a built-in test function at the rows of X (N, D); returns (N,).");
}

}  // namespace bayesgrasp::bind

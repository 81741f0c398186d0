// Argument conversions shared by the belief bindings (belief.cpp, belief_poses.cpp): running core
// calls without the GIL, state spaces, log weights, Python likelihoods, stacked action batches and
// entropy estimates. Errors are ValueErrors naming the argument.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bayesgrasp/belief/entropy.hpp"
#include "bayesgrasp/belief/particles.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace bl = bayesgrasp::belief;

/// Runs f without the GIL (the core's exceptions pass through to pybind11's translation).
template <class F>
auto released(F&& f) -> decltype(f()) {
  py::gil_scoped_release release;
  return f();
}

/// The state space; StateSpace validates the bounds and flags.
inline bl::StateSpace space_from(const DArray& low, const DArray& high, const py::object& wraps) {
  std::vector<bool> w;
  if (!wraps.is_none()) w = py::cast<std::vector<bool>>(wraps);
  return bl::StateSpace(vector(low, "low"), vector(high, "high"), w);
}

/// A 1-D array of log-weights or log-likelihoods (-inf allowed: zero weight; the core rejects
/// NaN and +inf).
inline Eigen::VectorXd log_weights_from(const DArray& a, const char* name) {
  if (a.ndim() != 1) throw py::value_error(std::string(name) + ": expected a 1-D array, got " + shape_str(a));
  return Eigen::Map<const Eigen::VectorXd>(a.data(), a.shape(0));
}

/// A vectorised Python callable (N, D) -> (N,) as a batch log-likelihood (GIL taken per call).
inline bl::BatchLogLikelihood likelihood_from(const py::object& obj, const char* name) {
  if (!PyCallable_Check(obj.ptr()))
    throw py::value_error(std::string(name) + ": expected a callable (N, D) -> (N,) of log-likelihoods");
  py::function fn = py::reinterpret_borrow<py::function>(obj);
  std::string nm(name);
  return [fn, nm](const bl::RowMatrixXd& X, Eigen::VectorXd& ll) {
    py::gil_scoped_acquire gil;
    py::array_t<double> arr({X.rows(), X.cols()});
    std::copy(X.data(), X.data() + X.size(), arr.mutable_data());
    DArray a = py::cast<DArray>(fn(arr));
    if (!(a.ndim() == 1 || (a.ndim() == 2 && a.shape(1) == 1)) || a.shape(0) != X.rows())
      throw py::value_error(nm + ": must return an array of shape (" + std::to_string(X.rows()) + ",), got " +
                            shape_str(a));
    ll = Eigen::Map<const Eigen::VectorXd>(a.data(), X.rows());
  };
}

/// mean/var as (A, N, K) or (N, K) (A = 1) arrays -> (A*N, K) matrices (the core checks the
/// rows against the particles and the values).
inline bl::RowMatrixXd stacked(const DArray& a, const char* name, py::ssize_t& n_actions) {
  if (a.ndim() == 2) {
    n_actions = 1;
    return Eigen::Map<const bl::RowMatrixXd>(a.data(), a.shape(0), a.shape(1));
  }
  if (a.ndim() != 3) throw py::value_error(std::string(name) + ": expected shape (A, N, K) or (N, K), got " + shape_str(a));
  n_actions = a.shape(0);
  return Eigen::Map<const bl::RowMatrixXd>(a.data(), a.shape(0) * a.shape(1), a.shape(2));
}

inline py::array_t<double> to_np(const bl::RowMatrixXd& m) { return to_numpy(m); }

inline py::tuple estimates(const std::vector<bl::EntropyEstimate>& est) {
  Eigen::VectorXd h(est.size()), se(est.size());
  for (size_t i = 0; i < est.size(); ++i) {
    h[i] = est[i].mean;
    se[i] = est[i].std_error;
  }
  return py::make_tuple(h, se);
}

}  // namespace bayesgrasp::bind

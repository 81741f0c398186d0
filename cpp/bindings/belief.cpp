// Bindings for the belief concept: particle beliefs (reweighting, resampling, Metropolis moves,
// roughening), entropy estimates, the expected posterior entropy of actions (Eq. 3.2), the planar
// relative pose and its inverse, and the GP measurement model. Thin: convert, release the GIL and
// re-acquire it only around calls of a Python likelihood; the core validates (its
// std::invalid_argument becomes ValueError). Warnings (all-zero likelihood recovery) are raised by
// python/bayesgrasp/belief.py from the returned flag.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bayesgrasp/belief/entropy.hpp"
#include "bayesgrasp/belief/measurement_model.hpp"
#include "bayesgrasp/belief/model_mixture.hpp"
#include "bayesgrasp/belief/particles.hpp"
#include "bayesgrasp/belief/pose_grid.hpp"
#include "bayesgrasp/belief/relative_pose.hpp"
#include "options.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace py = pybind11;
using namespace py::literals;
namespace bl = bayesgrasp::belief;

namespace {

/// A belief with its own seeded generator (Python-side object).
struct PyBelief {
  bl::ParticleBelief belief;
  bl::Rng rng;
};

/// Runs f without the GIL (the core's exceptions pass through to pybind11's translation).
template <class F>
auto released(F&& f) -> decltype(f()) {
  py::gil_scoped_release release;
  return f();
}

/// The state space; StateSpace validates the bounds and flags.
bl::StateSpace space_from(const DArray& low, const DArray& high, const py::object& wraps) {
  std::vector<bool> w;
  if (!wraps.is_none()) w = py::cast<std::vector<bool>>(wraps);
  return bl::StateSpace(vector(low, "low"), vector(high, "high"), w);
}

/// A 1-D array of log-weights or log-likelihoods (-inf allowed: zero weight; the core rejects
/// NaN and +inf).
Eigen::VectorXd log_weights_from(const DArray& a, const char* name) {
  if (a.ndim() != 1) throw py::value_error(std::string(name) + ": expected a 1-D array, got " + shape_str(a));
  return Eigen::Map<const Eigen::VectorXd>(a.data(), a.shape(0));
}

/// A vectorised Python callable (N, D) -> (N,) as a batch log-likelihood (GIL taken per call).
bl::BatchLogLikelihood likelihood_from(const py::object& obj, const char* name) {
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
bl::RowMatrixXd stacked(const DArray& a, const char* name, py::ssize_t& n_actions) {
  if (a.ndim() == 2) {
    n_actions = 1;
    return Eigen::Map<const bl::RowMatrixXd>(a.data(), a.shape(0), a.shape(1));
  }
  if (a.ndim() != 3) throw py::value_error(std::string(name) + ": expected shape (A, N, K) or (N, K), got " + shape_str(a));
  n_actions = a.shape(0);
  return Eigen::Map<const bl::RowMatrixXd>(a.data(), a.shape(0) * a.shape(1), a.shape(2));
}

py::array_t<double> to_np(const bl::RowMatrixXd& m) { return to_numpy(m); }

py::tuple estimates(const std::vector<bl::EntropyEstimate>& est) {
  Eigen::VectorXd h(est.size()), se(est.size());
  for (size_t i = 0; i < est.size(); ++i) {
    h[i] = est[i].mean;
    se[i] = est[i].std_error;
  }
  return py::make_tuple(h, se);
}

}  // namespace

namespace {

void def_belief_state(py::class_<PyBelief>& c) {
  c.def(py::init([](const DArray& particles, const DArray& low, const DArray& high, const py::object& wraps,
                    const py::object& log_weights, std::uint64_t seed) {
          bl::StateSpace s = space_from(low, high, wraps);
          bl::RowMatrixXd X = matrix(particles, "particles", -1, /*allow_empty=*/true);
          Eigen::VectorXd lw;
          if (!log_weights.is_none()) lw = log_weights_from(py::cast<DArray>(log_weights), "log_weights");
          return new PyBelief{bl::ParticleBelief(s, X, lw), bl::Rng(seed)};
        }),
        "particles"_a, "low"_a, "high"_a, "wraps"_a = py::none(), "log_weights"_a = py::none(), "seed"_a = 0,
        "particles (N, D) inside [low, high] (wrapping dims are wrapped into [low, high)); log_weights\n"
        "(N,) or None for uniform; seed for this belief's generator.")
      .def_static(
          "uniform",
          [](const DArray& low, const DArray& high, int n, const py::object& wraps, std::uint64_t seed) {
            bl::StateSpace s = space_from(low, high, wraps);
            bl::Rng rng(seed);
            return new PyBelief{bl::ParticleBelief::uniform(s, n, rng), rng};
          },
          "low"_a, "high"_a, "n"_a, "wraps"_a = py::none(), "seed"_a = 0, "n particles uniform in the box.")
      .def_static(
          "gaussian",
          [](const DArray& low, const DArray& high, const DArray& mean, const DArray& std, int n,
             const py::object& wraps, std::uint64_t seed) {
            bl::StateSpace s = space_from(low, high, wraps);
            bl::Rng rng(seed);
            return new PyBelief{bl::ParticleBelief::gaussian(s, vector(mean, "mean"), vector(std, "std"), n, rng), rng};
          },
          "low"_a, "high"_a, "mean"_a, "std"_a, "n"_a, "wraps"_a = py::none(), "seed"_a = 0,
          "n particles from N(mean, diag(std^2)), truncated to the box (wrapping dims wrapped).")
      .def_property_readonly("particles", [](const PyBelief& b) { return to_np(b.belief.particles()); },
                             "(N, D) particle states (a copy).")
      .def_property_readonly("log_weights", [](const PyBelief& b) { return Eigen::VectorXd(b.belief.log_weights()); },
                             "(N,) normalised log-weights.")
      .def_property_readonly("weights", [](const PyBelief& b) { return b.belief.weights(); }, "(N,) weights, sum 1.")
      .def_property_readonly("size", [](const PyBelief& b) { return b.belief.size(); })
      .def_property_readonly("dim", [](const PyBelief& b) { return b.belief.dim(); })
      .def_property_readonly("low", [](const PyBelief& b) { return b.belief.space().low; })
      .def_property_readonly("high", [](const PyBelief& b) { return b.belief.space().high; })
      .def_property_readonly("wraps",
                             [](const PyBelief& b) {
                               std::vector<bool> w(b.belief.dim(), false);
                               for (int k = 0; k < b.belief.dim(); ++k) w[k] = b.belief.space().wrap(k);
                               return w;
                             })
      .def("ess", [](const PyBelief& b) { return b.belief.ess(); }, "Effective sample size 1 / sum w^2.")
      .def("mean", [](const PyBelief& b) { return b.belief.mean(); },
           "Weighted mean (circular mean for wrapping dims).");
}

void def_belief_updates(py::class_<PyBelief>& c) {
  c.def(
       "reweight",
       [](PyBelief& b, const DArray& ll) { return b.belief.reweight(log_weights_from(ll, "log_likelihood")); },
       "log_likelihood"_a,
       "Adds log-likelihoods (N,) to the log-weights and normalises. Returns True if every likelihood\n"
       "was zero and the weights were reset to uniform (the recovery).")
      .def(
          "update",
          [](PyBelief& b, const py::object& fn) {
            const bl::BatchLogLikelihood f = likelihood_from(fn, "log_likelihood");
            return released([&] { return b.belief.update(f); });
          },
          "log_likelihood"_a,
          "Evaluates log_likelihood (vectorised callable (N, D) -> (N,)) once at all particles, then\n"
          "reweight(). Returns the recovery flag.")
      .def(
          "update_gp",
          [](PyBelief& b, const gp::GaussianProcess& model, const DArray& action, const DArray& measurement) {
            const Eigen::RowVectorXd a = vector(action, "action").transpose();
            const Eigen::RowVectorXd meas = vector(measurement, "measurement").transpose();
            return released([&] { return bl::gp_update(b.belief, model, a, meas); });
          },
          "gp"_a, "action"_a, "measurement"_a,
          "Bayes update with the GP measurement model in one C++ call: log-likelihood of measurement (P,)\n"
          "at every particle = the GP's log predictive density at relative_planar_pose(action, particle).\n"
          "Returns the recovery flag.")
      .def(
          "resample",
          [](PyBelief& b, const std::string& scheme, int n) {
            b.belief.resample(b.rng, bl::resampling_from_string(scheme), n);
          },
          "scheme"_a = "systematic", "n"_a = 0,
          "Resamples N (or n > 0) particles: 'systematic', 'stratified' or 'multinomial'; weights become uniform.")
      .def(
          "resample_if_needed",
          [](PyBelief& b, double threshold, const std::string& scheme) {
            return b.belief.resample_if_needed(b.rng, threshold, bl::resampling_from_string(scheme));
          },
          "threshold"_a = 0.5, "scheme"_a = "systematic", "Resamples if ess < threshold * N; returns whether it did.")
      .def(
          "metropolis",
          [](PyBelief& b, const py::object& fn, const DArray& step, int n_steps) {
            const bl::BatchLogLikelihood f = likelihood_from(fn, "log_target");
            const Eigen::VectorXd st = vector(step, "step");
            return released([&] { return b.belief.metropolis(f, st, n_steps, b.rng); });
          },
          "log_target"_a, "step"_a, "n_steps"_a = 1,
          "n_steps Metropolis random-walk sweeps (proposal std `step` per dim) under log_target, a\n"
          "vectorised callable (N, D) -> (N,) called once per sweep (plus once at the start). Proposals\n"
          "outside the box are rejected; wrapping dims wrap. Returns a MetropolisStats.")
      .def("roughen", [](PyBelief& b, double k) { b.belief.roughen(b.rng, k); }, "k"_a = 0.2,
           "Gordon et al. roughening: jitter std k * spread * N^(-1/D) per dimension.")
      .def("weight_entropy", [](const PyBelief& b) { return bl::weight_entropy(b.belief.log_weights()); },
           "-sum w log w of the weights (the thesis's weight-based estimate).")
      .def(
          "kde_entropy",
          [](const PyBelief& b, const std::string& bandwidth) {
            const bl::Bandwidth bw = bl::bandwidth_from_string(bandwidth);
            return released([&] {
              return bl::kde_entropy(b.belief.particles(), b.belief.log_weights(), b.belief.space(), bw);
            });
          },
          "bandwidth"_a = "scott", "Weighted Gaussian-KDE entropy by resubstitution (see kde_entropy).");
}

void bind_particle_belief(py::module_& m) {
  py::class_<bl::MetropolisStats>(m, "MetropolisStats", "What a run of Metropolis sweeps did.")
      .def_readonly("acceptance_rate", &bl::MetropolisStats::acceptance_rate,
                    "acceptance_rate : float\n    Accepted proposals / (particles x sweeps).")
      .def_readonly("evaluations", &bl::MetropolisStats::evaluations,
                    "evaluations : int\n    Rows passed to the log-target (particles x (sweeps + 1)).")
      .def("__repr__", [](const bl::MetropolisStats& s) {
        return "MetropolisStats(acceptance_rate=" + py::repr(py::float_(s.acceptance_rate)).cast<std::string>() +
               ", evaluations=" + std::to_string(s.evaluations) + ")";
      });

  py::class_<PyBelief> belief(m, "ParticleBelief",
                              "Weighted particles over a box-bounded state (wrapping dims for angles) with its\n"
                              "own seeded generator. Use bayesgrasp.belief.ParticleBelief (adds warnings).");
  def_belief_state(belief);
  def_belief_updates(belief);
}

void bind_entropy(py::module_& m) {
  m.def(
      "resample_indices",
      [](const DArray& weights, int n, const std::string& scheme, std::uint64_t seed) {
        bl::Rng rng(seed);
        return bl::resample_indices(vector(weights, "weights"), n, bl::resampling_from_string(scheme), rng);
      },
      "weights"_a, "n"_a, "scheme"_a = "systematic", "seed"_a = 0,
      "Indices of n particles drawn with probabilities proportional to weights (>= 0).");

  m.def("weight_entropy", [](const DArray& lw) { return bl::weight_entropy(log_weights_from(lw, "log_weights")); },
        "log_weights"_a, "-sum w log w of the normalised weights exp(log_weights).");

  m.def(
      "kde_entropy",
      [](const DArray& particles, const DArray& log_weights, const DArray& low, const DArray& high,
         const py::object& wraps, const std::string& bandwidth) {
        const bl::StateSpace s = space_from(low, high, wraps);
        const bl::RowMatrixXd X = matrix(particles, "particles");
        const Eigen::VectorXd lw = log_weights_from(log_weights, "log_weights");
        const bl::Bandwidth bw = bl::bandwidth_from_string(bandwidth);
        return released([&] { return bl::kde_entropy(X, lw, s, bw); });
      },
      "particles"_a, "log_weights"_a, "low"_a, "high"_a, "wraps"_a = py::none(), "bandwidth"_a = "scott",
      "Weighted Gaussian-KDE entropy -sum_i w_i log p(x_i); kernel covariance f^2 C (C the weighted\n"
      "covariance, f by Scott's or Silverman's rule with n_eff = 1/sum w^2), as scipy's gaussian_kde.");

  m.def(
      "expected_posterior_entropy",
      [](const DArray& log_weights, const DArray& mean, const DArray& var, int n_samples, std::uint64_t seed,
         int n_threads) {
        const Eigen::VectorXd lw = log_weights_from(log_weights, "log_weights");
        py::ssize_t a_m = 0, a_v = 0;
        const bl::RowMatrixXd M = stacked(mean, "mean", a_m);
        const bl::RowMatrixXd V = stacked(var, "var", a_v);
        if (a_m != a_v) throw py::value_error("var: expected the same shape as mean");
        return estimates(released([&] {
          return bl::expected_posterior_entropy_batch(lw, M, V, static_cast<int>(a_m), n_samples, seed, n_threads);
        }));
      },
      "log_weights"_a, "mean"_a, "var"_a, "n_samples"_a = 100, "seed"_a = 0, "n_threads"_a = 1,
      "Expected posterior weight entropy of actions (Eq. 3.2). mean, var: the predictive mean and\n"
      "variance (with noise) of the measurement at every particle, (N, K) for one action or (A, N, K)\n"
      "for A actions. Per sample: particle j ~ w, m ~ N(mean_j, var_j), reweight all particles by\n"
      "N(m; mean_i, var_i), weight entropy; averaged. The same seed gives the same draws for every\n"
      "action. n_threads: threads over the actions (0 = all cores). Returns (entropy (A,), standard\n"
      "error (A,)).");

  m.def(
      "expected_posterior_entropy_gp",
      [](const gp::GaussianProcess& model, const DArray& particles, const DArray& log_weights, const DArray& actions,
         int n_samples, std::uint64_t seed, int n_threads) {
        const bl::RowMatrixXd P = matrix(particles, "particles");
        const Eigen::VectorXd lw = log_weights_from(log_weights, "log_weights");
        const bl::RowMatrixXd A = matrix(actions, "actions");
        return estimates(released(
            [&] { return bl::gp_expected_posterior_entropy(model, P, lw, A, n_samples, seed, n_threads); }));
      },
      "gp"_a, "particles"_a, "log_weights"_a, "actions"_a, "n_samples"_a = 100, "seed"_a = 0, "n_threads"_a = 1,
      "Expected posterior entropy of A actions under a GP measurement model, in one C++ call: one GP\n"
      "prediction (mean, variance with noise) at the relative poses of all (action, particle) pairs,\n"
      "then expected_posterior_entropy. particles (N, 3) planar poses; actions (A, input_dim).");
}

/// Binds a planar pose map f(grasps (R, 3 + extra), poses (N, 3)) under `name`.
using PoseMap = bl::RowMatrixXd (*)(const bl::RowMatrixXd&, const bl::RowMatrixXd&);
void def_pose_map(py::module_& m, const char* name, PoseMap f, const char* grasps, const char* doc) {
  m.def(
      name,
      [f, grasps](const DArray& g, const DArray& poses) { return to_np(f(matrix(g, grasps), matrix(poses, "poses"))); },
      py::arg(grasps), "poses"_a, doc);
}

void bind_planar_pose(py::module_& m) {
  def_pose_map(m, "relative_planar_pose", bl::relative_planar_pose, "actions",
               "Grasp poses relative to object poses, for all pairs: actions (A, 3 + extra), poses (N, 3) ->\n"
               "(A*N, 3 + extra), row a*N + j = (R(-yaw_j)(a_xy - o_xy), wrap(a_yaw - yaw_j), extra_a).");
  def_pose_map(m, "compose_planar_pose", bl::compose_planar_pose, "relative",
               "The inverse of relative_planar_pose, for all pairs: relative grasps (R, 3 + extra) in object\n"
               "frames, poses (N, 3) -> world grasps (R*N, 3 + extra), row r*N + j =\n"
               "(o_xy_j + R(yaw_j) r_xy, wrap(r_yaw + yaw_j), extra_r).");
  def_pose_map(m, "compose_planar_pose_paired", bl::compose_planar_pose_paired, "relative",
               "compose_planar_pose one to one: relative (N, 3 + extra) and poses (N, 3) -> (N, 3 + extra),\n"
               "row i = (o_xy_i + R(yaw_i) r_xy_i, wrap(r_yaw_i + yaw_i), extra_i).");
}

void bind_pose_grid(py::module_& m) {
  py::class_<bl::RelativePoseGrid>(m, "RelativePoseGrid",
                                   "A regular grid over relative grasp poses (x, y, yaw) with C channels,\n"
                                   "trilinear interpolation, yaw periodic (a tabulated planning model).")
      .def(py::init([](const DArray& lo, const DArray& hi, int nx, int ny, int nyaw, const DArray& values,
                       const DArray& outside) {
             const Eigen::VectorXd l = vector(lo, "lo", 2), h = vector(hi, "hi", 2);
             bl::RowMatrixXd V = matrix(values, "values");
             if (outside.ndim() != 1) throw py::value_error("outside: expected a 1-D array");
             Eigen::Map<const Eigen::VectorXd> o(outside.data(), outside.shape(0));
             return new bl::RelativePoseGrid({l[0], l[1]}, {h[0], h[1]}, nx, ny, nyaw, std::move(V), Eigen::VectorXd(o));
           }),
           "lo"_a, "hi"_a, "nx"_a, "ny"_a, "nyaw"_a, "values"_a, "outside"_a,
           "Nodes x_i = lo[0] + i (hi[0]-lo[0])/(nx-1), likewise y, yaw_k = -pi + 2 pi k / nyaw; values\n"
           "(nx*ny*nyaw, C), row (ix*ny + iy)*nyaw + k; outside (C,): value where x or y is outside the\n"
           "grid, NaN to clamp to the edge.")
      .def_property_readonly("channels", &bl::RelativePoseGrid::channels)
      .def_property_readonly("shape", [](const bl::RelativePoseGrid& g) {
        return py::make_tuple(g.nx(), g.ny(), g.nyaw(), g.channels());
      })
      .def(
          "interpolate",
          [](const bl::RelativePoseGrid& g, const DArray& rel) {
            const bl::RowMatrixXd R = matrix(rel, "rel", -1, true);
            return to_np(released([&] { return g.interpolate(R); }));
          },
          "rel"_a, "Values at relative poses (P, 3) -> (P, C).")
      .def(
          "interpolate_pairs",
          [](const bl::RelativePoseGrid& g, const DArray& actions, const DArray& poses, int c0, int nc, int n_threads) {
            const bl::RowMatrixXd A = matrix(actions, "actions"), P = matrix(poses, "poses");
            return to_np(released([&] { return g.interpolate_pairs(A, P, c0, nc, n_threads); }));
          },
          "actions"_a, "poses"_a, "c0"_a = 0, "nc"_a = 1, "n_threads"_a = 1,
          "Channels [c0, c0+nc) at every action (A, 3) relative to every pose (N, 3): (A*N, nc),\n"
          "row a*N + j. n_threads: threads over the actions (0 = all cores).")
      .def(
          "expected",
          [](const bl::RelativePoseGrid& g, const DArray& actions, const DArray& poses, const DArray& weights,
             int channel, int n_threads) {
            const bl::RowMatrixXd A = matrix(actions, "actions"), P = matrix(poses, "poses");
            const Eigen::VectorXd w = vector(weights, "weights");
            return released([&] { return g.expected(A, P, w, channel, n_threads); });
          },
          "actions"_a, "poses"_a, "weights"_a, "channel"_a = 0, "n_threads"_a = 1,
          "sum_j w_j value(action relative to pose_j) for every action (A,): Eq. 3.1's integral over\n"
          "a particle belief when the channel is P(S | A, O).")
      .def(
          "expected_posterior_entropy",
          [](const bl::RelativePoseGrid& g, const DArray& actions, const DArray& poses, const DArray& log_weights,
             int mean_c0, int var_c0, int k, int n_samples, std::uint64_t seed, int n_threads) {
            const bl::RowMatrixXd A = matrix(actions, "actions"), P = matrix(poses, "poses");
            const Eigen::VectorXd lw = log_weights_from(log_weights, "log_weights");
            return estimates(released([&] {
              return g.expected_posterior_entropy(A, P, lw, mean_c0, var_c0, k, n_samples, seed, n_threads);
            }));
          },
          "actions"_a, "poses"_a, "log_weights"_a, "mean_c0"_a, "var_c0"_a, "k"_a, "n_samples"_a = 100,
          "seed"_a = 0, "n_threads"_a = 1,
          "Expected posterior weight entropy (Eq. 3.2) of every action with the measurement mean in\n"
          "channels [mean_c0, mean_c0+k) and its variance in [var_c0, var_c0+k). Returns (h (A,), se (A,)).");
}

void bind_model_mixture(py::module_& m) {
  OptionClass<bl::ModelPoseOptions>(m, "ModelPoseOptions", "Options of Eq. 4.4's per-model MAP pose update.")
      .field("prior_std", &bl::ModelPoseOptions::prior_std, "ndarray (3,)",
             "sd of the Gaussian prior around the previous pose (m, m, rad)")
      .field("measurement_noise", &bl::ModelPoseOptions::measurement_noise, "float",
             "joint-angle noise sd (rad) added to the predictive variance")
      .field("trust_region", &bl::ModelPoseOptions::trust_region, "TrustRegionOptions",
             "the dogleg trust region's options (scaled coordinates)")
      .validator([](const bl::ModelPoseOptions& o) { o.validate(); })
      .finish();
  py::class_<bl::ModelPoseUpdate>(m, "ModelPoseUpdate", "One model's MAP pose after a grasp (Eq. 4.4).")
      .def_readonly("pose", &bl::ModelPoseUpdate::pose, "pose : ndarray (3,)\n    p_i(t) = (x, y, yaw), yaw in [-pi, pi)")
      .def_readonly("log_likelihood", &bl::ModelPoseUpdate::log_likelihood,
                    "log_likelihood : float\n    log L_i of the measurement at p_i(t)")
      .def_readonly("log_prior", &bl::ModelPoseUpdate::log_prior,
                    "log_prior : float\n    log N(p_i(t); p_i(t-1), S) up to its constant")
      .def_readonly("evaluations", &bl::ModelPoseUpdate::evaluations, "evaluations : int\n    objective evaluations")
      .def_readonly("converged", &bl::ModelPoseUpdate::converged, "converged : bool\n    a tolerance was met");
  py::class_<bl::ModelWeightUpdate>(m, "ModelWeightUpdate", "Eq. 4.5's weights.")
      .def_readonly("weights", &bl::ModelWeightUpdate::weights, "weights : ndarray (M,)\n    normalised weights")
      .def_readonly("underflow", &bl::ModelWeightUpdate::underflow,
                    "underflow : bool\n    every likelihood was zero: the previous weights were kept");
  m.def(
      "map_model_poses",
      [](const std::vector<const bl::RelativePoseGrid*>& grids, int mean_c0, int var_c0, int k, const DArray& grasp,
         const DArray& measurement, const DArray& prior_poses, const bl::ModelPoseOptions& o, int threads) {
        const Eigen::Vector3d g = vector(grasp, "grasp", 3);
        const Eigen::VectorXd mv = vector(measurement, "measurement");
        const RowMatrixXd P = matrix(prior_poses, "prior_poses", 3, true);
        py::gil_scoped_release release;
        return bl::map_model_poses(grids, bl::MeasurementChannels{mean_c0, var_c0, k}, g, mv, P, o, threads);
      },
      "grids"_a, "mean_c0"_a, "var_c0"_a, "k"_a, "grasp"_a, "measurement"_a, "prior_poses"_a,
      "options"_a = bl::ModelPoseOptions(), "threads"_a = 1,
      "Eq. 4.4 for every model: its MAP pose after the top grasp `grasp` (x, y, yaw) read `measurement`.");
  m.def(
      "measurement_log_likelihood",
      [](const bl::RelativePoseGrid& g, int mean_c0, int var_c0, int k, const DArray& grasp, const DArray& measurement,
         const DArray& poses, double noise) {
        return bl::measurement_log_likelihood(g, bl::MeasurementChannels{mean_c0, var_c0, k}, vector(grasp, "grasp", 3),
                                              vector(measurement, "measurement"), matrix(poses, "poses", 3, true), noise);
      },
      "grid"_a, "mean_c0"_a, "var_c0"_a, "k"_a, "grasp"_a, "measurement"_a, "poses"_a, "measurement_noise"_a = 0.0,
      "log N(m; mu(G - p), var(G - p) + s_n^2) for poses p (N, 3).");
  m.def(
      "update_model_weights",
      [](const DArray& ll, const DArray& previous, bool recursive) {
        Eigen::Map<const Eigen::VectorXd> l(ll.data(), ll.ndim() == 1 ? ll.shape(0) : 0);
        if (ll.ndim() != 1) throw py::value_error("log_likelihoods: expected shape (M,), got " + shape_str(ll));
        return bl::update_model_weights(l, vector(previous, "previous"), recursive);
      },
      "log_likelihoods"_a, "previous"_a, "recursive"_a = false,
      "Eq. 4.5: w_i = L_i / sum_j L_j (recursive: w_i ~ w_i(t-1) L_i); all zero keeps the previous weights.");
}

}  // namespace

void bind_belief(py::module_& m) {
  bind_particle_belief(m);
  bind_entropy(m);
  bind_planar_pose(m);
  bind_pose_grid(m);
  bind_model_mixture(m);
}

}  // namespace bayesgrasp::bind

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
#include "belief_args.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace py = pybind11;
using namespace py::literals;
namespace bl = bayesgrasp::belief;

void bind_pose_beliefs(py::module_& m);

namespace {

/// A belief with its own seeded generator (Python-side object).
struct PyBelief {
  bl::ParticleBelief belief;
  bl::Rng rng;
};

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

}  // namespace

void bind_belief(py::module_& m) {
  bind_particle_belief(m);
  bind_entropy(m);
  bind_pose_beliefs(m);
}

}  // namespace bayesgrasp::bind

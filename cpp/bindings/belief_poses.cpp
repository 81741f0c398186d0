// Bindings of the belief concept's planar poses: the relative pose of a grasp and its inverse, the
// pose grid of the GP measurement model, and Eq. 4.4-4.5's per-model pose and weight updates of a
// model mixture. Thin: convert and release the GIL; the core validates (ValueError naming the field).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bayesgrasp/belief/measurement_model.hpp"
#include "bayesgrasp/belief/model_mixture.hpp"
#include "bayesgrasp/belief/pose_grid.hpp"
#include "bayesgrasp/belief/relative_pose.hpp"
#include "belief_args.hpp"
#include "options.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace py = pybind11;
using namespace py::literals;

namespace {

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

/// The joint particle belief over (model, pose): one model's resampling and jitter.
void bind_model_particles(py::module_& m) {
  m.attr("LOG_MIN_LIKELIHOOD") = bl::kLogMinLikelihood;
  m.def(
      "resample_and_jitter",
      [](const DArray& poses, const DArray& log_weights, const DArray& jitter_std, double threshold,
         std::uint64_t seed) {
        bl::RowMatrixXd P = matrix(poses, "poses", 3);
        Eigen::VectorXd lw = log_weights_from(log_weights, "log_weights");
        const Eigen::Vector3d s = vec3(jitter_std, "jitter_std");
        bl::Rng rng(seed);
        const bool did = bl::resample_and_jitter(P, lw, s, threshold, rng);
        return py::make_tuple(did, to_np(P), lw);
      },
      "poses"_a, "log_weights"_a, "jitter_std"_a, "threshold"_a = 0.5, "seed"_a = 0,
      "One model's particles (N, 3) after an update: systematic resampling when the ESS is below\n"
      "threshold * N, then N(0, jitter_std^2) jitter (yaw wrapped), the model's total weight kept.\n"
      "Returns (resampled, poses, log_weights).");
}

}  // namespace

void bind_pose_beliefs(py::module_& m) {
  bind_planar_pose(m);
  bind_pose_grid(m);
  bind_model_mixture(m);
  bind_model_particles(m);
}

}  // namespace bayesgrasp::bind

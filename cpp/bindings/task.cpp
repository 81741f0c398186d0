// Bindings for cpp/bayesgrasp/task: Eq. 4.1's pose densities and grasp mixture, local pose
// coordinates for the optimisers, and the open hand's clearance from the table and a cloud.
#include <pybind11/stl.h>

#include "bayesgrasp/task/grasp_mixture.hpp"
#include "bayesgrasp/task/hand_clearance.hpp"
#include "bayesgrasp/task/pose_density.hpp"
#include "options.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

using namespace bayesgrasp::task;

namespace {

/// Eq. 4.1's pose density (an option class: its kind and scales).
void bind_density(py::module_& m) {
  py::enum_<DensityKind>(m, "DensityKind", "Form of the pose density around a task grasp (Eq. 4.1).")
      .value("gaussian", DensityKind::Gaussian)
      .value("regularised", DensityKind::RegularisedGaussian)
      .value("laplace", DensityKind::Laplace);

  OptionClass<PoseDensity> density(m, "PoseDensity", R"doc(A density over hand poses around a task grasp.

With d_t the translation distance and d_R the rotation angle between the candidate and the grasp:
Gaussian exp(-(d_t^2/s_t^2 + d_R^2/s_R^2)/2); regularised Gaussian (1 - lambda) Gauss(s) +
lambda Gauss(kappa s); Laplace exp(-(d_t/s_t + d_R/s_R)). 1 at the grasp.)doc");
  density.field("kind", &PoseDensity::kind, "DensityKind", "gaussian, regularised or laplace")
      .field("translation_scale", &PoseDensity::translation_scale, "float", "s_t (m)")
      .field("rotation_scale", &PoseDensity::rotation_scale, "float", "s_R (rad)")
      .field("wide_weight", &PoseDensity::wide_weight, "float",
             "lambda, the wide component's weight (regularised only)")
      .field("wide_factor", &PoseDensity::wide_factor, "float",
             "kappa, the wide component's scale multiple (regularised only)")
      .validator([](const PoseDensity& d) { d.validate(); })
      .finish()
      .def("__call__", [](const PoseDensity& d, double dt, double dr) { d.validate(); return d(dt, dr); },
           py::arg("dt"), py::arg("dr"), "The density at translation distance dt (m) and rotation angle dr (rad).");
}

/// Eq. 4.1's grasp mixture and its values, and the local pose coordinates it plans in.
void bind_mixture(py::module_& m) {
  py::class_<MixtureValues>(m, "MixtureValues", "Eq. 4.1's objective at a batch of candidate hand poses.")
      .def_readonly("value", &MixtureValues::value, "value : ndarray (N,)\n    J(A)")
      .def_readonly("per_model", &MixtureValues::per_model,
                    "per_model : ndarray (N, M)\n    each model's share of J(A) (empty unless asked for)")
      .def_readonly("dominant", &MixtureValues::dominant,
                    "dominant : ndarray (N,)\n    the component contributing most (-1 where J = 0)");

  py::class_<GraspMixture>(m, "GraspMixture", R"doc(Eq. 4.1's mixture: task grasps of the training
models carried into the scene, each with weight psi(q_ik) phi(delta_i).)doc")
      .def(py::init([](const DArray& grasps, const DArray& weights, const std::vector<int>& models, int num_models) {
             return GraspMixture(poses(grasps, "grasps"), vector(weights, "weights"), models, num_models);
           }),
           py::arg("grasps"), py::arg("weights"), py::arg("models"), py::arg("num_models"),
           "grasps (K, 4, 4) in the scene frame; weights (K,) >= 0; models (K,) model index of each.")
      .def_property_readonly("size", &GraspMixture::size)
      .def_property_readonly("num_models", &GraspMixture::num_models)
      .def(
          "evaluate",
          [](const GraspMixture& g, const DArray& candidates, const PoseDensity& d, bool per_model, int threads) {
            const std::vector<Iso3> c = poses(candidates, "candidates");
            py::gil_scoped_release release;
            return g.evaluate(c, d, per_model, threads);
          },
          py::arg("candidates"), py::arg("density"), py::arg("per_model") = false, py::arg("threads") = 1,
          "J at candidate hand poses (N, 4, 4); threads 0 = all cores.")
      .def(
          "evaluate_local",
          [](const GraspMixture& g, const DArray& reference, const DArray& X, const PoseDensity& d, int threads) {
            const Iso3 ref = pose(reference, "reference");
            const LocalPoses L = matrix(X, "X", 6, true);
            const std::vector<Iso3> c = poses_from_local(ref, L);
            py::gil_scoped_release release;
            return Eigen::VectorXd(g.evaluate(c, d, false, threads).value);
          },
          py::arg("reference"), py::arg("X"), py::arg("density"), py::arg("threads") = 1,
          "J at poses given by local coordinates X (N, 6) around a reference pose (see poses_from_local).");

  m.def(
      "poses_from_local",
      [](const DArray& reference, const DArray& X) {
        return to_numpy(poses_from_local(pose(reference, "reference"), matrix(X, "X", 6, true)));
      },
      py::arg("reference"), py::arg("X"),
      "Poses (N, 4, 4) from rows (t, r) of X (N, 6): rotation exp([r]) R_ref, translation t_ref + t.");
}

/// The open hand's clearance of the table and the cloud.
void bind_clearance(py::module_& m) {
  OptionClass<ClearanceOptions>(m, "ClearanceOptions", "What the open hand must be clear of.")
      .field("table", &ClearanceOptions::table, "bool", "the plane z = 0 is an obstacle")
      .field("margin", &ClearanceOptions::margin, "float", "shapes grown by this (m)")
      .validator([](const ClearanceOptions& o) { validate(o); })
      .finish();

  py::class_<Clearance>(m, "Clearance", "Intrusions into the open hand at each candidate pose (m, 0 = clear).")
      .def_readonly("table", &Clearance::table, "table : ndarray (N,)\n    depth below z = 0")
      .def_readonly("cloud", &Clearance::cloud, "cloud : ndarray (N,)\n    deepest cloud point inside a hand shape");

  m.def(
      "hand_clearance",
      [](const HandModel& hand, const DArray& q, const DArray& hand_poses, const DArray& cloud,
         const ClearanceOptions& options, int threads) {
        const Eigen::VectorXd qv = vector(q, "q");
        const std::vector<Iso3> P = poses(hand_poses, "poses");
        const CloudPoints C = matrix(cloud, "cloud", 3, true);
        py::gil_scoped_release release;
        return hand_clearance(hand, qv, P, C, options, threads);
      },
      py::arg("hand"), py::arg("q"), py::arg("poses"), py::arg("cloud"), py::arg("options") = ClearanceOptions(),
      py::arg("threads") = 1, "Intrusions of the table and the cloud (K, 3) into the hand at joints q, per pose.");
}

}  // namespace

void bind_task(py::module_& m) {
  bind_density(m);
  bind_mixture(m);
  bind_clearance(m);
}

}  // namespace bayesgrasp::bind

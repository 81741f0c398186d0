// Bindings of the registration (vision concept): its option classes (one per step), its results
// and the calls (register_models, Registrar, model_from_mesh). Thin: the bindings check shapes and
// convert; the core validates values (std::invalid_argument naming the field becomes ValueError);
// work is done in C++ with the GIL released.
#include <pybind11/eigen.h>
#include <pybind11/native_enum.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>

#include "bayesgrasp/geometry/surface_sampling.hpp"
#include "bayesgrasp/vision/registration.hpp"
#include "options.hpp"
#include "validate.hpp"
#include "vision_args.hpp"

namespace bayesgrasp::bind {

namespace py = pybind11;
using namespace bayesgrasp::vision;

namespace {

// ---- registration: inputs
std::vector<ModelCloud> models_arg(const py::list& models) {
  std::vector<ModelCloud> ms;
  for (std::size_t i = 0; i < models.size(); ++i) {
    const std::string name = "models[" + std::to_string(i) + "]";
    ModelCloud mc;
    if (py::isinstance<SurfaceSamples>(models[i])) {
      mc.surface = models[i].cast<SurfaceSamples>();
    } else {
      const py::tuple t = pair_at(models, i, name, "points, normals");
      mc.surface.points = points_arg(t[0].cast<DArray>(), (name + " points").c_str(), false);
      mc.surface.normals = points_arg(t[1].cast<DArray>(), (name + " normals").c_str(), false);
    }
    if (mc.surface.points.rows() != mc.surface.normals.rows())
      throw py::value_error(name + ": points and normals differ in length");
    ms.push_back(std::move(mc));
  }
  return ms;
}

// The viewpoint's shape; the core checks that it is finite.
std::optional<Vec3> viewpoint_arg(const py::object& viewpoint) {
  if (viewpoint.is_none()) return std::nullopt;
  const DArray a = viewpoint.cast<DArray>();
  if (a.ndim() != 1 || a.shape(0) != 3)
    throw py::value_error("viewpoint: expected shape (3,), got " + shape_str(a));
  return Vec3(a.data()[0], a.data()[1], a.data()[2]);
}

std::optional<std::vector<int>> indices_arg(const py::object& models) {
  if (models.is_none()) return std::nullopt;
  try {
    return models.cast<std::vector<int>>();
  } catch (const py::cast_error&) {
    throw py::value_error("models: expected a sequence of model indices");
  }
}

void bind_options(py::module_& m) {
  py::native_enum<FeatureEstimator>(m, "FeatureEstimator", "enum.Enum",
                                    "Which normal and FPFH estimator prepares the clouds for matching.")
      .value("Ours", FeatureEstimator::Ours, "one shared radius-grid search per point, each pair computed once")
      .value("Pcl", FeatureEstimator::Pcl, "PCL's NormalEstimationOMP + FPFHEstimationOMP (same definitions)")
      .finalize();

  OptionClass<FeatureOptions> features(m, "FeatureOptions", "Normals and FPFH descriptors.");
  features.field("normal_radius", &FeatureOptions::normal_radius, "float", "x voxel: PCA neighbourhood of a normal")
      .field("feature_radius", &FeatureOptions::feature_radius, "float", "x voxel: FPFH neighbourhood")
      .field("estimator", &FeatureOptions::estimator, "FeatureEstimator", "ours or PCL's")
      .validator([](const FeatureOptions& o) { validate(o); })
      .finish();

  OptionClass<CorrespondenceOptions> corr(m, "CorrespondenceOptions", "Feature correspondences scene <-> model.");
  corr.field("neighbours", &CorrespondenceOptions::neighbours, "int", "per scene feature: its k nearest model features")
      .field("reverse", &CorrespondenceOptions::reverse, "bool", "also each model feature's nearest scene feature")
      .field("hellinger", &CorrespondenceOptions::hellinger, "bool",
             "compare sqrt(histograms) (Hellinger distance) instead of raw L2")
      .validator([](const CorrespondenceOptions& o) { validate(o); })
      .finish();

  OptionClass<RansacOptions> ransac(m, "RansacOptions", "The seeded RANSAC over correspondences and its hypotheses.");
  ransac.field("iterations", &RansacOptions::iterations, "int", "maximum per restart")
      .field("min_iterations", &RansacOptions::min_iterations, "int", "per restart, whatever the confidence bound says")
      .field("confidence", &RansacOptions::confidence, "float", "of the adaptive stopping bound, in (0, 1)")
      .field("edge_similarity", &RansacOptions::edge_similarity, "float",
             "pre-rejection: corresponding edge lengths agree to this ratio, in (0, 1)")
      .field("max_normal_angle", &RansacOptions::max_normal_angle, "float",
             "pre-rejection: matched normals agree within this angle (rad)")
      .field("restarts", &RansacOptions::restarts, "int", "independent runs (seeds derived from the call's seed)")
      .field("candidates", &RansacOptions::candidates, "int", "distinct hypotheses kept per restart (by consensus)")
      .field("hypotheses", &RansacOptions::hypotheses, "int",
             "best candidates over all restarts (by fitting error) refined by a coarse ICP")
      .validator([](const RansacOptions& o) { validate(o); })
      .finish();

  OptionClass<IcpOptions> icp(m, "IcpOptions", "Point-to-plane ICP against the model's dense surface samples.");
  icp.field("distance", &IcpOptions::distance, "float", "x voxel: correspondence distance")
      .field("iterations", &IcpOptions::iterations, "int", "full ICP of the chosen hypothesis")
      .field("tolerance", &IcpOptions::tolerance, "float", "stop when the update is below this (rad, m)")
      .field("coarse_points", &IcpOptions::coarse_points, "int",
             "scene subsample for the coarse ICP of every hypothesis")
      .field("coarse_iterations", &IcpOptions::coarse_iterations, "int", "iterations of the coarse ICP")
      .validator([](const IcpOptions& o) { validate(o); })
      .finish();

  OptionClass<UpPrior> up(m, "UpPrior",
                          "A model resting on the table keeps its +z (model frame) near `up` (cloud frame).");
  up.field("enabled", &UpPrior::enabled, "bool", "False: 6-DOF search, no tilt limit, no up penalty")
      .field("upright", &UpPrior::upright, "bool",
             "4-DOF hypotheses (yaw about up + translation, 2 correspondences); else 6-DOF with a tilt limit")
      .field("up", &UpPrior::up, "ndarray (3,)", "the table normal in the cloud's frame")
      .field("max_tilt", &UpPrior::max_tilt, "float", "rad: 6-DOF hypotheses tilting the model's up more are rejected")
      .field("weight", &UpPrior::weight, "float", "selection cost += weight (1 - cos tilt) / 2")
      .validator([](const UpPrior& o) { validate(o); })
      .finish();

  OptionClass<RegistrationOptions> reg(m, "RegistrationOptions",
                                       "Options of the registration, one struct per step; radii and distances are "
                                       "multiples of voxel. validate() checks them (ValueError naming the field).");
  reg.field("voxel", &RegistrationOptions::voxel, "float", "m: downsampling leaf, the unit of every radius and distance")
      .field("inlier_distance", &RegistrationOptions::inlier_distance, "float",
             "x voxel: RANSAC inliers, fitness, RMSE and the cut-off tau of delta")
      .field("weight_sigma", &RegistrationOptions::weight_sigma, "float", "x voxel: sigma of phi(delta)")
      .field("min_scene_points", &RegistrationOptions::min_scene_points, "int",
             "scene points with normals after downsampling below which every model fails (TooFewScenePoints)")
      .field("model_samples", &RegistrationOptions::model_samples, "int",
             "points sampled per model mesh; 0: area / (voxel/3)^2, clamped to [2000, 200000]")
      .field("threads", &RegistrationOptions::threads, "int", "over models and scene features; 0 = all cores")
      .field("features", &RegistrationOptions::features, "FeatureOptions", "normals and FPFH")
      .field("correspondences", &RegistrationOptions::correspondences, "CorrespondenceOptions", "feature matching")
      .field("ransac", &RegistrationOptions::ransac, "RansacOptions", "global registration")
      .field("icp", &RegistrationOptions::icp, "IcpOptions", "local refinement")
      .field("up_prior", &RegistrationOptions::up_prior, "UpPrior", "upright models on a table")
      .validator([](const RegistrationOptions& o) { validate(o); })
      .finish();
}

// ---- registration: results
void bind_results(py::module_& m) {
  py::native_enum<RegistrationStatus>(m, "RegistrationStatus", "enum.Enum", "Why a model did or did not register.")
      .value("Ok", RegistrationStatus::Ok)
      .value("NoSurface", RegistrationStatus::NoSurface, "the model has no surface points")
      .value("InvalidModel", RegistrationStatus::InvalidModel, "its points or normals are not finite")
      .value("TooFewModelPoints", RegistrationStatus::TooFewModelPoints,
             "fewer than 3 model points with normals after downsampling")
      .value("TooFewScenePoints", RegistrationStatus::TooFewScenePoints,
             "fewer than min_scene_points scene points with normals after downsampling")
      .value("NoHypothesis", RegistrationStatus::NoHypothesis, "RANSAC found no transform")
      .value("NonFiniteTransform", RegistrationStatus::NonFiniteTransform, "the refinement diverged")
      .finalize();

  py::class_<RegistrationResult> r(m, "RegistrationResult", "One model's registration against a cloud.");
  readonly(r, "status", &RegistrationResult::status, "RegistrationStatus", "Ok, or why the model did not register");
  readonly(r, "reason", &RegistrationResult::reason, "str", "human-readable, when status is not Ok");
  readonly(r, "transform", &RegistrationResult::transform, "ndarray (4, 4)",
           "model frame -> cloud frame (identity when status is not Ok)");
  readonly(r, "fitness", &RegistrationResult::fitness, "float",
           "fraction of downsampled cloud points within the inlier distance");
  readonly(r, "rmse", &RegistrationResult::rmse, "float", "RMS distance of those inliers, m");
  readonly(r, "delta", &RegistrationResult::delta, "float",
           "fitting error sqrt(mean min(d_i, tau)^2), m (Eq. 4.1's delta_i)");
  readonly(r, "phi", &RegistrationResult::phi, "float",
           "phi(delta) = exp(-delta^2 / (2 sigma^2)), sigma = weight_sigma voxels, unnormalised");
  readonly(r, "up_cos", &RegistrationResult::up_cos, "float", "cos of the angle between the model's +z and `up`");
  readonly(r, "cost", &RegistrationResult::cost, "float", "selection cost of the chosen hypothesis");
  readonly(r, "scene_points", &RegistrationResult::scene_points, "int", "cloud points after downsampling");
  readonly(r, "model_points", &RegistrationResult::model_points, "int", "model points after downsampling");
  readonly(r, "ransac_iterations", &RegistrationResult::ransac_iterations, "int", "total over restarts");
  readonly(r, "time_features", &RegistrationResult::time_features, "float",
           "s: the cloud's features (register_models: plus the model's preparation)");
  readonly(r, "time_global", &RegistrationResult::time_global, "float", "s: correspondences and RANSAC");
  readonly(r, "time_icp", &RegistrationResult::time_icp, "float", "s: hypothesis choice, ICP and fit measures");
  r.def_property_readonly("success", &RegistrationResult::success, "success : bool\n    status is Ok");
  r.def("__repr__", [](const RegistrationResult& x) {
    return "RegistrationResult(status=" + std::string(py::str(py::cast(x.status))) + ", delta=" +
           std::to_string(x.delta) + ", phi=" + std::to_string(x.phi) + ", fitness=" + std::to_string(x.fitness) + ")";
  });

  py::class_<PreparedModelInfo> info(m, "PreparedModelInfo", "A model's preparation in a Registrar.");
  readonly(info, "status", &PreparedModelInfo::status, "RegistrationStatus",
           "Ok, NoSurface, InvalidModel or TooFewModelPoints");
  readonly(info, "reason", &PreparedModelInfo::reason, "str", "human-readable, when status is not Ok");
  readonly(info, "points", &PreparedModelInfo::points, "int", "points after downsampling");
  readonly(info, "time", &PreparedModelInfo::time, "float", "s spent preparing it");
  info.def_property_readonly("ok", &PreparedModelInfo::ok, "ok : bool\n    status is Ok");
}

// ---- registration: calls
void bind_calls(py::module_& m) {

  m.def(
      "register_models",
      [](const DArray& cloud, const py::list& models, const RegistrationOptions& options, std::uint64_t seed,
         const py::object& viewpoint) {
        const Points S = points_arg(cloud, "cloud", true);
        const std::vector<ModelCloud> ms = models_arg(models);
        const std::optional<Vec3> vp = viewpoint_arg(viewpoint);
        py::gil_scoped_release release;
        return register_models(S, ms, options, seed, vp);
      },
      py::arg("cloud"), py::arg("models"), py::arg("options") = RegistrationOptions(), py::arg("seed") = 0,
      py::arg("viewpoint") = py::none(),
      "Registers a partial cloud (N, 3; NaN rows dropped) against models [(points (M,3), outward normals "
      "(M,3)) or SurfaceSamples, ...] (see model_from_mesh). One shot: the models are prepared (downsampled, "
      "normals, FPFH) inside the call; use Registrar to prepare them once for many clouds. `viewpoint`: the "
      "camera centre (cloud normals point towards it). Returns one RegistrationResult per model; "
      "time_features includes the model's preparation.");

  py::class_<Registrar>(m, "Registrar",
                        "Object models prepared once (radius grid over the dense samples, downsampled cloud, "
                        "normals, FPFH) and registered against any number of partial clouds. Same options, seed "
                        "and viewpoint: the same result as register_models.")
      .def(py::init([](const RegistrationOptions& options, const py::list& models) {
             const std::vector<ModelCloud> ms = models_arg(models);
             auto r = std::make_unique<Registrar>(options);
             py::gil_scoped_release release;
             r->add_models(ms);
             return r;
           }),
           py::arg("options") = RegistrationOptions(), py::arg("models") = py::list(),
           "Validates the options and prepares the models (see add_models).")
      .def(
          "add_models",
          [](Registrar& r, const py::list& models) {
            const std::vector<ModelCloud> ms = models_arg(models);
            py::gil_scoped_release release;
            return r.add_models(ms);
          },
          py::arg("models"),
          "Prepares and appends models [(points (M,3), outward normals (M,3)) or SurfaceSamples, ...]; returns "
          "the index of the first. A model that cannot be prepared is kept with a failed status.")
      .def(
          "register",
          [](const Registrar& r, const DArray& cloud, std::uint64_t seed, const py::object& viewpoint,
             const py::object& models) {
            const Points S = points_arg(cloud, "cloud", true);
            const std::optional<Vec3> vp = viewpoint_arg(viewpoint);
            const std::optional<std::vector<int>> idx = indices_arg(models);
            py::gil_scoped_release release;
            return idx ? r.register_scene(S, seed, vp, *idx) : r.register_scene(S, seed, vp);
          },
          py::arg("cloud"), py::arg("seed") = 0, py::arg("viewpoint") = py::none(), py::arg("models") = py::none(),
          "Registers a partial cloud (N, 3; NaN rows dropped) against the prepared models (`models`: indices, "
          "None for all). Returns one RegistrationResult per model (time_features: the cloud's features only).")
      .def("__len__", &Registrar::size)
      .def_property_readonly("options", [](const Registrar& r) { return r.options(); },
                             "options : RegistrationOptions\n    a copy of the options (fixed at construction)")
      .def("model_info", &Registrar::model_info, py::arg("i"), "PreparedModelInfo of model i.");

  m.def(
      "model_from_mesh",
      [](const DArray& vertices, const IArray& faces, const RegistrationOptions& options, std::uint64_t seed) {
        const TriMesh M = mesh(vertices, faces, "mesh");
        py::gil_scoped_release release;
        return model_from_mesh(M, options, seed).surface;
      },
      py::arg("vertices"), py::arg("faces"), py::arg("options") = RegistrationOptions(), py::arg("seed") = 0,
      "Surface samples of a mesh for registration: options.model_samples points (0: area / (voxel/3)^2, "
      "clamped to [2000, 200000]), a SurfaceSamples. ValueError if the mesh has no area.");
}

}  // namespace

void bind_registration(py::module_& m) {
  bind_options(m);
  bind_results(m);
  bind_calls(m);
}

}  // namespace bayesgrasp::bind

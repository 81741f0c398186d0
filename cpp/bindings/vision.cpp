// Bindings for the vision concept: simulated depth camera, table segmentation, registration.
// Thin: the bindings check shapes and convert; the core validates values (std::invalid_argument
// naming the argument becomes ValueError); work is done in C++ with the GIL released.
#include <pybind11/eigen.h>
#include <pybind11/native_enum.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <memory>
#include <optional>

#include "bayesgrasp/geometry/surface_sampling.hpp"
#include "bayesgrasp/vision/camera.hpp"
#include "bayesgrasp/vision/registration.hpp"
#include "bayesgrasp/vision/segmentation.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace py = pybind11;
using namespace bayesgrasp::vision;

namespace {

Intrinsics intrinsics(int width, int height, double fx, double fy, double cx, double cy) {
  if (width <= 0) throw py::value_error("width: must be positive, got " + std::to_string(width));
  if (height <= 0) throw py::value_error("height: must be positive, got " + std::to_string(height));
  if (static_cast<long>(width) * height > 50'000'000) throw py::value_error("width * height: image too large");
  Intrinsics K;
  K.width = width;
  K.height = height;
  K.fx = positive(fx, "fx");
  K.fy = positive(fy, "fy");
  K.cx = std::isnan(cx) ? (width - 1) / 2.0 : finite(cx, "cx");
  K.cy = std::isnan(cy) ? (height - 1) / 2.0 : finite(cy, "cy");
  return K;
}

// Item i of a Python list of 2-tuples, or a ValueError naming it ("name: expected a (what) tuple").
py::tuple pair_at(const py::list& list, std::size_t i, const std::string& name, const char* what) {
  py::tuple t;
  try {
    t = list[i].cast<py::tuple>();
  } catch (const py::cast_error&) {
    throw py::value_error(name + ": expected a (" + what + ") tuple");
  }
  if (t.size() != 2) throw py::value_error(name + ": expected a (" + what + ") tuple");
  return t;
}

std::vector<TriMesh> meshes_arg(const py::list& meshes) {
  std::vector<TriMesh> out;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const std::string name = "meshes[" + std::to_string(i) + "]";
    const py::tuple t = pair_at(meshes, i, name, "vertices, faces");
    out.push_back(mesh(t[0].cast<DArray>(), t[1].cast<IArray>(), name.c_str()));
  }
  return out;
}

Points points_arg(const DArray& a, const char* name, bool allow_nan) {
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(std::string(name) + ": expected shape (N, 3), got " + shape_str(a));
  Points P = Eigen::Map<const Points>(a.data(), a.shape(0), 3);
  if (!allow_nan && !P.allFinite()) throw py::value_error(std::string(name) + ": contains NaN or infinity");
  for (Eigen::Index i = 0; i < P.rows(); ++i)
    if (P.row(i).array().isInf().any()) throw py::value_error(std::string(name) + ": contains infinity");
  return P;
}

py::array_t<double> points_out(const Points& P) {
  py::array_t<double> out({static_cast<py::ssize_t>(P.rows()), static_cast<py::ssize_t>(3)});
  std::copy(P.data(), P.data() + P.size(), out.mutable_data());
  return out;
}

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

// ---- registration: option classes with a "name : type\n    description" docstring per field,
// a keyword constructor (unknown keywords are a ValueError naming them), __repr__ and copies.
template <typename C>
class OptionClass {
 public:
  OptionClass(py::module_& m, const char* name, const char* doc) : cls_(m, name, doc), name_(name) {}

  template <typename T>
  OptionClass& field(const char* name, T C::*member, const char* type, const char* doc) {
    cls_.def_readwrite(name, member, (std::string(name) + " : " + type + "\n    " + doc).c_str());
    fields_->push_back(name);
    return *this;
  }

  void finish() {
    const auto fields = fields_;
    const std::string cname = name_;
    cls_.def(py::init([fields, cname](const py::kwargs& kw) {
               py::object self = py::cast(C{});
               for (const auto& item : kw) {
                 const std::string key = py::str(item.first);
                 if (std::find(fields->begin(), fields->end(), key) == fields->end())
                   throw py::value_error(key + ": not a field of " + cname);
                 self.attr(key.c_str()) = item.second;
               }
               return self.cast<C>();
             }),
             ("Defaults, with any field given by keyword: " + cname + "(name=value, ...).").c_str())
        .def("__repr__",
             [fields, cname](const py::object& self) {
               std::string s = cname + "(";
               for (std::size_t i = 0; i < fields->size(); ++i)
                 s += (i ? ", " : "") + (*fields)[i] + "=" + std::string(py::repr(self.attr((*fields)[i].c_str())));
               return s + ")";
             })
        .def("__copy__", [](const C& c) { return C(c); })
        .def("__deepcopy__", [](const C& c, const py::object&) { return C(c); }, py::arg("memo"));
  }

  py::class_<C>& cls() { return cls_; }

 private:
  py::class_<C> cls_;
  std::string name_;
  std::shared_ptr<std::vector<std::string>> fields_ = std::make_shared<std::vector<std::string>>();
};

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
      .finish();

  OptionClass<CorrespondenceOptions> corr(m, "CorrespondenceOptions", "Feature correspondences scene <-> model.");
  corr.field("neighbours", &CorrespondenceOptions::neighbours, "int", "per scene feature: its k nearest model features")
      .field("reverse", &CorrespondenceOptions::reverse, "bool", "also each model feature's nearest scene feature")
      .field("hellinger", &CorrespondenceOptions::hellinger, "bool",
             "compare sqrt(histograms) (Hellinger distance) instead of raw L2")
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
      .finish();

  OptionClass<IcpOptions> icp(m, "IcpOptions", "Point-to-plane ICP against the model's dense surface samples.");
  icp.field("distance", &IcpOptions::distance, "float", "x voxel: correspondence distance")
      .field("iterations", &IcpOptions::iterations, "int", "full ICP of the chosen hypothesis")
      .field("tolerance", &IcpOptions::tolerance, "float", "stop when the update is below this (rad, m)")
      .field("coarse_points", &IcpOptions::coarse_points, "int", "scene subsample for the coarse ICP of every hypothesis")
      .field("coarse_iterations", &IcpOptions::coarse_iterations, "int", "iterations of the coarse ICP")
      .finish();

  OptionClass<UpPrior> up(m, "UpPrior",
                          "A model resting on the table keeps its +z (model frame) near `up` (cloud frame).");
  up.field("enabled", &UpPrior::enabled, "bool", "False: 6-DOF search, no tilt limit, no up penalty")
      .field("upright", &UpPrior::upright, "bool",
             "4-DOF hypotheses (yaw about up + translation, 2 correspondences); else 6-DOF with a tilt limit")
      .field("up", &UpPrior::up, "ndarray (3,)", "the table normal in the cloud's frame")
      .field("max_tilt", &UpPrior::max_tilt, "float", "rad: 6-DOF hypotheses tilting the model's up more are rejected")
      .field("weight", &UpPrior::weight, "float", "selection cost += weight (1 - cos tilt) / 2")
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
      .finish();
  reg.cls().def("validate", [](const RegistrationOptions& o) { validate(o); },
                "Raises ValueError naming the first bad field.");
}

// ---- registration: results
template <typename C, typename T>
void readonly(py::class_<C>& cls, const char* name, T C::*member, const char* type, const char* doc) {
  cls.def_readonly(name, member, (std::string(name) + " : " + type + "\n    " + doc).c_str());
}

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
void bind_registration(py::module_& m) {
  bind_options(m);
  bind_results(m);

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

void bind_vision(py::module_& m) {
  m.def(
      "look_at",
      [](const DArray& eye, const DArray& target, const DArray& up) {
        const Vec3 e = vector(eye, "eye", 3), t = vector(target, "target", 3), u = vector(up, "up", 3);
        Iso3 T;
        try {
          T = look_at(e, t, u);
        } catch (const std::invalid_argument& ex) {
          throw py::value_error(std::string("eye, target, up: ") + ex.what());
        }
        Eigen::Matrix<double, 4, 4, Eigen::RowMajor> M = T.matrix();
        return M;
      },
      py::arg("eye"), py::arg("target"), py::arg("up") = Eigen::Vector3d::UnitZ(),
      "Camera-to-world pose (4x4) of a camera at `eye` looking at `target`; camera frame x right, "
      "y down, z forward; image up as close as possible to `up`.");

  m.def(
      "render",
      [](const py::list& meshes, const DArray& pose, int width, int height, double fx, double fy, double cx,
         double cy, bool table, double table_z, const DArray& table_center, const DArray& table_half_extents,
         bool noise, std::uint64_t seed, double sigma_a, double sigma_b, double baseline, double disparity_step,
         double max_incidence_deg, double edge_jump, double edge_drop_prob, double min_depth, double max_depth) {
        const Intrinsics K = intrinsics(width, height, fx, fy, cx, cy);
        const Iso3 T = bind::pose(pose, "pose");
        const std::vector<TriMesh> ms = meshes_arg(meshes);
        Table tb;
        tb.enabled = table;
        tb.z = finite(table_z, "table_z");
        const Eigen::VectorXd c = vector(table_center, "table_center", 2);
        if (table_half_extents.ndim() != 1 || table_half_extents.shape(0) != 2)
          throw py::value_error("table_half_extents: expected shape (2,)");
        tb.center_x = c(0);
        tb.center_y = c(1);
        tb.half_x = table_half_extents.data()[0];
        tb.half_y = table_half_extents.data()[1];
        if (!(tb.half_x > 0) || !(tb.half_y > 0) || std::isnan(tb.half_x) || std::isnan(tb.half_y))
          throw py::value_error("table_half_extents: must be positive (inf allowed)");
        NoiseModel nm;
        nm.enabled = noise;
        nm.seed = seed;
        nm.sigma_a = finite(sigma_a, "sigma_a");
        nm.sigma_b = finite(sigma_b, "sigma_b");
        if (sigma_a < 0 || sigma_b < 0) throw py::value_error("sigma_a, sigma_b: must be non-negative");
        nm.baseline = positive(baseline, "baseline");
        nm.disparity_step = finite(disparity_step, "disparity_step");
        if (disparity_step < 0) throw py::value_error("disparity_step: must be non-negative");
        nm.max_incidence = finite(max_incidence_deg, "max_incidence_deg") * 3.14159265358979323846 / 180.0;
        nm.edge_jump = positive(edge_jump, "edge_jump");
        nm.edge_drop_prob = finite(edge_drop_prob, "edge_drop_prob");
        if (edge_drop_prob < 0 || edge_drop_prob > 1) throw py::value_error("edge_drop_prob: must be in [0, 1]");
        nm.min_depth = finite(min_depth, "min_depth");
        nm.max_depth = positive(max_depth, "max_depth");
        RenderResult r;
        {
          py::gil_scoped_release release;
          r = render(K, T, ms, tb, nm);
        }
        return py::make_tuple(r.depth, r.label);
      },
      py::arg("meshes"), py::arg("pose"), py::arg("width") = 640, py::arg("height") = 480, py::arg("fx") = 525.0,
      py::arg("fy") = 525.0, py::arg("cx") = std::numeric_limits<double>::quiet_NaN(),
      py::arg("cy") = std::numeric_limits<double>::quiet_NaN(), py::arg("table") = false, py::arg("table_z") = 0.0,
      py::arg("table_center") = Eigen::Vector2d::Zero(), py::arg("table_half_extents") = Eigen::Vector2d(0.5, 0.5),
      py::arg("noise") = true, py::arg("seed") = 0, py::arg("sigma_a") = 0.0012, py::arg("sigma_b") = 0.0019,
      py::arg("baseline") = 0.075, py::arg("disparity_step") = 0.125, py::arg("max_incidence_deg") = 78.0,
      py::arg("edge_jump") = 0.02, py::arg("edge_drop_prob") = 0.8, py::arg("min_depth") = 0.4,
      py::arg("max_depth") = 4.0,
      "Ray-casts the meshes (list of (V (N,3), F (M,3)) in the world frame) and an optional table "
      "rectangle at height table_z from camera pose `pose` (4x4 camera->world). Returns (depth (H,W) "
      "camera-frame z in metres, NaN where nothing is measured; label (H,W) int: mesh index, -2 table, "
      "-1 nothing, before noise). cx, cy default to the image centre. Noise (seeded): axial Gaussian "
      "sigma_a + sigma_b (z - 0.4)^2, disparity quantisation, grazing (> max_incidence_deg) and "
      "edge dropout, depth range [min_depth, max_depth].");

  m.def(
      "depth_to_points",
      [](const DArray& depth, const DArray& pose, double fx, double fy, double cx, double cy, bool world,
         bool organised) {
        if (depth.ndim() != 2) throw py::value_error("depth: expected shape (H, W), got " + shape_str(depth));
        const int H = static_cast<int>(depth.shape(0)), W = static_cast<int>(depth.shape(1));
        const Intrinsics K = intrinsics(W, H, fx, fy, cx, cy);
        const Iso3 T = bind::pose(pose, "pose");
        const DepthImage D = Eigen::Map<const DepthImage>(depth.data(), H, W);
        for (Eigen::Index i = 0; i < D.size(); ++i)
          if (std::isinf(D.data()[i])) throw py::value_error("depth: contains infinity (use NaN for missing)");
        Points P;
        {
          py::gil_scoped_release release;
          P = depth_to_points(K, D, T, world, organised);
        }
        return points_out(P);
      },
      py::arg("depth"), py::arg("pose"), py::arg("fx") = 525.0, py::arg("fy") = 525.0,
      py::arg("cx") = std::numeric_limits<double>::quiet_NaN(), py::arg("cy") = std::numeric_limits<double>::quiet_NaN(),
      py::arg("world") = true, py::arg("organised") = false,
      "Back-projects a depth image (H, W) to points: organised -> (H*W, 3) in pixel order with NaN rows "
      "for missing pixels, else (N, 3) valid points only; world frame (via pose) or camera frame.");

  m.def(
      "segment_table",
      [](const DArray& cloud, double plane_threshold, int plane_iterations, double min_height, double max_height,
         double cluster_tolerance, int min_cluster_size, const DArray& up) {
        const Points P = points_arg(cloud, "cloud", true);
        SegmentationParams sp;
        sp.plane_threshold = positive(plane_threshold, "plane_threshold");
        if (plane_iterations < 1) throw py::value_error("plane_iterations: must be positive");
        sp.plane_iterations = plane_iterations;
        sp.min_height = finite(min_height, "min_height");
        sp.max_height = finite(max_height, "max_height");
        if (!(max_height > min_height)) throw py::value_error("max_height: must exceed min_height");
        sp.cluster_tolerance = positive(cluster_tolerance, "cluster_tolerance");
        if (min_cluster_size < 1) throw py::value_error("min_cluster_size: must be positive");
        sp.min_cluster_size = min_cluster_size;
        sp.up = vector(up, "up", 3);
        if (!(sp.up.norm() > 0)) throw py::value_error("up: must be non-zero");
        SegmentationResult r;
        {
          py::gil_scoped_release release;
          try {
            r = segment_table(P, sp);
          } catch (const std::invalid_argument& e) {
            py::gil_scoped_acquire acquire;
            throw py::value_error(std::string("cloud: ") + e.what());
          }
        }
        py::dict d;
        d["plane"] = Eigen::Vector4d(r.plane);
        d["plane_inliers"] = py::array_t<int>(static_cast<py::ssize_t>(r.plane_inliers.size()), r.plane_inliers.data());
        py::list cl;
        for (const auto& c : r.clusters) cl.append(py::array_t<int>(static_cast<py::ssize_t>(c.size()), c.data()));
        d["clusters"] = cl;
        return d;
      },
      py::arg("cloud"), py::arg("plane_threshold") = 0.006, py::arg("plane_iterations") = 1000,
      py::arg("min_height") = 0.008, py::arg("max_height") = 1.0, py::arg("cluster_tolerance") = 0.01,
      py::arg("min_cluster_size") = 50, py::arg("up") = Eigen::Vector3d::UnitZ(),
      "Table-top segmentation of an (N, 3) cloud (NaN rows ignored): the dominant plane by RANSAC "
      "(normal oriented along `up`), points between min_height and max_height above it, Euclidean "
      "clusters. Returns {'plane': (a, b, c, d), 'plane_inliers': rows, 'clusters': [rows, ...] largest first}.");

  bind_registration(m);

  m.def(
      "rotation_error",
      [](const DArray& Ra, const DArray& Rb, py::object axis) {
        const RowMatrixXd A = matrix(Ra, "Ra", 3), B = matrix(Rb, "Rb", 3);
        if (A.rows() != 3 || B.rows() != 3) throw py::value_error("Ra, Rb: expected shape (3, 3)");
        Vec3 ax = Vec3::Zero();
        if (!axis.is_none()) ax = vector(axis.cast<DArray>(), "axis", 3);
        return rotation_error(Mat3(A), Mat3(B), ax);
      },
      py::arg("Ra"), py::arg("Rb"), py::arg("axis") = py::none(),
      "Angle (rad) between rotations; with `axis` (model frame) the rotation about it is ignored "
      "(bodies of revolution): the angle between Ra axis and Rb axis.");
}

}  // namespace bayesgrasp::bind

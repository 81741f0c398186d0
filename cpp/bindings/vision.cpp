// Bindings for the vision concept: simulated depth camera, table segmentation, registration.
// Thin: arguments are validated here (ValueError naming the argument), work is done in C++
// with the GIL released.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>

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

py::dict result_dict(const RegistrationResult& r) {
  py::dict d;
  d["success"] = r.success;
  d["reason"] = r.reason;
  py::array_t<double> T({4, 4});
  Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(T.mutable_data()) = r.transform;
  d["transform"] = T;
  d["fitness"] = r.fitness;
  d["rmse"] = r.rmse;
  d["delta"] = r.delta;
  d["phi"] = r.phi;
  d["weight"] = r.weight;
  d["up_cos"] = r.up_cos;
  d["cost"] = r.cost;
  d["scene_points"] = r.scene_points;
  d["model_points"] = r.model_points;
  d["ransac_iterations"] = r.ransac_iterations;
  d["time_features"] = r.time_features;
  d["time_global"] = r.time_global;
  d["time_icp"] = r.time_icp;
  return d;
}

RegistrationParams params_arg(double voxel, bool up_prior, bool upright, const DArray& up, double max_tilt_deg,
                              int restarts, int ransac_iterations, int hypotheses, int icp_iterations,
                              int feature_neighbours, double normal_radius, double feature_radius,
                              double inlier_distance, double icp_distance, double weight_sigma, int min_scene_points,
                              int threads, bool reverse_matches, bool hellinger, bool pcl_features) {
  RegistrationParams p;
  p.voxel = positive(voxel, "voxel");
  p.use_up_prior = up_prior;
  p.upright = upright;
  p.up = vector(up, "up", 3);
  if (!(p.up.norm() > 0)) throw py::value_error("up: must be non-zero");
  p.max_tilt = positive(max_tilt_deg, "max_tilt_deg") * 3.14159265358979323846 / 180.0;
  auto pos_int = [](int v, const char* name) {
    if (v < 1) throw py::value_error(std::string(name) + ": must be positive");
    return v;
  };
  p.restarts = pos_int(restarts, "restarts");
  p.ransac_iterations = pos_int(ransac_iterations, "ransac_iterations");
  p.hypotheses = pos_int(hypotheses, "hypotheses");
  if (icp_iterations < 0) throw py::value_error("icp_iterations: must be non-negative");
  p.icp_iterations = icp_iterations;
  p.feature_neighbours = pos_int(feature_neighbours, "feature_neighbours");
  p.normal_radius = positive(normal_radius, "normal_radius");
  p.feature_radius = positive(feature_radius, "feature_radius");
  p.inlier_distance = positive(inlier_distance, "inlier_distance");
  p.icp_distance = positive(icp_distance, "icp_distance");
  p.weight_sigma = positive(weight_sigma, "weight_sigma");
  p.min_scene_points = pos_int(min_scene_points, "min_scene_points");
  if (threads < 0) throw py::value_error("threads: must be non-negative");
  p.threads = threads;
  p.reverse_matches = reverse_matches;
  p.hellinger = hellinger;
  p.pcl_features = pcl_features;
  return p;
}

std::vector<ModelCloud> models_arg(const py::list& models, bool allow_empty = false) {
  std::vector<ModelCloud> ms;
  for (std::size_t i = 0; i < models.size(); ++i) {
    const std::string name = "models[" + std::to_string(i) + "]";
    const py::tuple t = pair_at(models, i, name, "points, normals");
    ModelCloud mc;
    mc.surface.points = points_arg(t[0].cast<DArray>(), (name + " points").c_str(), false);
    mc.surface.normals = points_arg(t[1].cast<DArray>(), (name + " normals").c_str(), false);
    if (mc.surface.points.rows() != mc.surface.normals.rows())
      throw py::value_error(name + ": points and normals differ in length");
    ms.push_back(std::move(mc));
  }
  if (ms.empty() && !allow_empty) throw py::value_error("models: is empty");
  return ms;
}

Points scene_arg(const DArray& cloud) {
  Points S = points_arg(cloud, "cloud", true);
  bool any_finite = false;
  for (Eigen::Index i = 0; i < S.rows() && !any_finite; ++i) any_finite = S.row(i).allFinite();
  if (!any_finite) throw py::value_error("cloud: has no finite points");
  return S;
}

std::optional<Vec3> viewpoint_arg(const py::object& viewpoint) {
  if (viewpoint.is_none()) return std::nullopt;
  return Vec3(vector(viewpoint.cast<DArray>(), "viewpoint", 3));
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

  m.def(
      "sample_surface",
      [](const DArray& V, const IArray& F, int n, std::uint64_t seed) {
        const TriMesh M = mesh(V, F, "mesh");
        if (n <= 0) throw py::value_error("n: must be positive");
        SurfaceSamples s;
        try {
          py::gil_scoped_release release;
          s = sample_surface(M, n, seed);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(std::string("mesh: ") + e.what());
        }
        return py::make_tuple(points_out(s.points), points_out(s.normals));
      },
      py::arg("vertices"), py::arg("faces"), py::arg("n"), py::arg("seed") = 0,
      "n points sampled uniformly (area-weighted) on a mesh surface, with the faces' unit normals: (points, normals).");

  m.def("surface_area", [](const DArray& V, const IArray& F) { return surface_area(mesh(V, F, "mesh")); },
        py::arg("vertices"), py::arg("faces"), "Total area of a triangle mesh (m^2).");

  m.def(
      "register_models",
      [](const DArray& scene, const py::list& models, double voxel, std::uint64_t seed, bool up_prior, bool upright,
         const DArray& up, double max_tilt_deg, py::object viewpoint, int restarts, int ransac_iterations,
         int hypotheses, int icp_iterations, int feature_neighbours, double normal_radius, double feature_radius,
         double inlier_distance, double icp_distance, double weight_sigma, int min_scene_points, int threads,
         bool reverse_matches, bool hellinger, bool pcl_features) {
        const Points S = scene_arg(scene);
        RegistrationParams p = params_arg(voxel, up_prior, upright, up, max_tilt_deg, restarts, ransac_iterations,
                                          hypotheses, icp_iterations, feature_neighbours, normal_radius,
                                          feature_radius, inlier_distance, icp_distance, weight_sigma,
                                          min_scene_points, threads, reverse_matches, hellinger, pcl_features);
        p.seed = seed;
        const std::optional<Vec3> vp = viewpoint_arg(viewpoint);
        p.has_viewpoint = vp.has_value();
        if (vp) p.viewpoint = *vp;
        const std::vector<ModelCloud> ms = models_arg(models);
        std::vector<RegistrationResult> res;
        {
          py::gil_scoped_release release;
          res = register_models(S, ms, p);
        }
        py::list out;
        for (const auto& r : res) out.append(result_dict(r));
        return out;
      },
      py::arg("cloud"), py::arg("models"), py::arg("voxel") = 0.005, py::arg("seed") = 0, py::arg("up_prior") = true,
      py::arg("upright") = true, py::arg("up") = Eigen::Vector3d::UnitZ(), py::arg("max_tilt_deg") = 60.0,
      py::arg("viewpoint") = py::none(), py::arg("restarts") = 3, py::arg("ransac_iterations") = 20000,
      py::arg("hypotheses") = 4, py::arg("icp_iterations") = 30, py::arg("feature_neighbours") = 2,
      py::arg("normal_radius") = 2.0, py::arg("feature_radius") = 5.0, py::arg("inlier_distance") = 1.5,
      py::arg("icp_distance") = 1.5, py::arg("weight_sigma") = 0.5, py::arg("min_scene_points") = 30,
      py::arg("threads") = 0, py::arg("reverse_matches") = true, py::arg("hellinger") = true,
      py::arg("pcl_features") = false,
      "Registers a partial cloud (N, 3; NaN rows dropped) against models [(points (M,3), outward normals "
      "(M,3)), ...] (surface samples; see model_from_mesh). Radii and distances are multiples of `voxel`. "
      "One shot: the models are prepared (downsampled, normals, FPFH) inside the call; use Registrar to "
      "prepare them once for many clouds. Returns one dict per model: success, reason, transform (4x4 "
      "model->scene), fitness, rmse, delta, phi = exp(-delta^2 / (2 (weight_sigma voxel)^2)), weight (phi "
      "normalised over successful models), up_cos, cost, scene_points, model_points, ransac_iterations, "
      "time_features/global/icp (s; time_features includes the model's preparation).");

  py::class_<Registrar>(m, "Registrar",
                        "Object models prepared once (dense k-d tree, downsampled cloud, normals, FPFH) and "
                        "registered against any number of partial clouds. Same parameters, seed and viewpoint: "
                        "the same result as register_models.")
      .def(py::init([](const py::list& models, double voxel, bool up_prior, bool upright, const DArray& up,
                       double max_tilt_deg, int restarts, int ransac_iterations, int hypotheses, int icp_iterations,
                       int feature_neighbours, double normal_radius, double feature_radius, double inlier_distance,
                       double icp_distance, double weight_sigma, int min_scene_points, int threads,
                       bool reverse_matches, bool hellinger, bool pcl_features) {
             const RegistrationParams p = params_arg(voxel, up_prior, upright, up, max_tilt_deg, restarts,
                                                     ransac_iterations, hypotheses, icp_iterations,
                                                     feature_neighbours, normal_radius, feature_radius,
                                                     inlier_distance, icp_distance, weight_sigma, min_scene_points,
                                                     threads, reverse_matches, hellinger, pcl_features);
             const std::vector<ModelCloud> ms = models_arg(models, true);
             auto r = std::make_unique<Registrar>(p);
             {
               py::gil_scoped_release release;
               r->add_models(ms);
             }
             return r;
           }),
           py::arg("models"), py::arg("voxel") = 0.005, py::arg("up_prior") = true, py::arg("upright") = true,
           py::arg("up") = Eigen::Vector3d::UnitZ(), py::arg("max_tilt_deg") = 60.0, py::arg("restarts") = 3,
           py::arg("ransac_iterations") = 20000, py::arg("hypotheses") = 4, py::arg("icp_iterations") = 30,
           py::arg("feature_neighbours") = 2, py::arg("normal_radius") = 2.0, py::arg("feature_radius") = 5.0,
           py::arg("inlier_distance") = 1.5, py::arg("icp_distance") = 1.5, py::arg("weight_sigma") = 0.5,
           py::arg("min_scene_points") = 30, py::arg("threads") = 0, py::arg("reverse_matches") = true,
           py::arg("hellinger") = true, py::arg("pcl_features") = false,
           "Prepares the models [(points (M,3), outward normals (M,3)), ...] (may be empty; see add_models) "
           "with the parameters of register_models.")
      .def(
          "add_models",
          [](Registrar& r, const py::list& models) {
            const std::vector<ModelCloud> ms = models_arg(models);
            py::gil_scoped_release release;
            return r.add_models(ms);
          },
          py::arg("models"), "Prepares and appends models; returns the index of the first.")
      .def(
          "register",
          [](const Registrar& r, const DArray& cloud, std::uint64_t seed, py::object viewpoint, py::object models) {
            const Points S = scene_arg(cloud);
            const std::optional<Vec3> vp = viewpoint_arg(viewpoint);
            std::vector<int> idx;
            if (!models.is_none()) {
              try {
                idx = models.cast<std::vector<int>>();
              } catch (const py::cast_error&) {
                throw py::value_error("models: expected a sequence of model indices");
              }
              if (idx.empty()) throw py::value_error("models: is empty");
              for (int i : idx)
                if (i < 0 || i >= r.size())
                  throw py::value_error("models: index " + std::to_string(i) + " out of range [0, " +
                                        std::to_string(r.size()) + ")");
            }
            if (r.size() == 0) throw py::value_error("models: the registrar has no models");
            std::vector<RegistrationResult> res;
            {
              py::gil_scoped_release release;
              res = r.register_scene(S, seed, vp, idx);
            }
            py::list out;
            for (const auto& x : res) out.append(result_dict(x));
            return out;
          },
          py::arg("cloud"), py::arg("seed") = 0, py::arg("viewpoint") = py::none(), py::arg("models") = py::none(),
          "Registers a partial cloud (N, 3; NaN rows dropped) against the prepared models (`models`: indices, "
          "None for all). Returns one dict per model as register_models does (time_features: the cloud's "
          "features only); weights are normalised over the models of the call.")
      .def("__len__", &Registrar::size)
      .def_property_readonly("voxel", [](const Registrar& r) { return r.params().voxel; })
      .def(
          "model_info",
          [](const Registrar& r, int i) {
            if (i < 0 || i >= r.size()) throw py::value_error("i: model index out of range");
            py::dict d;
            d["ok"] = r.model_ok(i);
            d["reason"] = r.model_reason(i);
            d["model_points"] = r.model_points(i);
            d["time"] = r.model_time(i);
            return d;
          },
          py::arg("i"), "{'ok', 'reason', 'model_points' (after downsampling), 'time' (s to prepare)} of model i.");

  m.def(
      "model_from_mesh",
      [](const DArray& V, const IArray& F, double voxel, std::uint64_t seed, int samples) {
        const TriMesh M = mesh(V, F, "mesh");
        RegistrationParams p;
        p.voxel = positive(voxel, "voxel");
        if (samples < 0) throw py::value_error("samples: must be non-negative");
        p.model_samples = samples;
        ModelCloud mc;
        try {
          py::gil_scoped_release release;
          mc = model_from_mesh(M, p, seed);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(std::string("mesh: ") + e.what());
        }
        return py::make_tuple(points_out(mc.surface.points), points_out(mc.surface.normals));
      },
      py::arg("vertices"), py::arg("faces"), py::arg("voxel") = 0.005, py::arg("seed") = 0, py::arg("samples") = 0,
      "Surface samples of a mesh for registration: `samples` points (0: area / (voxel/3)^2, clamped to "
      "[2000, 200000]); returns (points, normals). ValueError if the mesh has no area.");

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

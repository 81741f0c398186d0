// Bindings for the vision concept's camera and segmentation: the simulated depth camera (its
// intrinsics, table and noise as option classes), back-projection, table-top segmentation (its
// options and result bound), look_at and rotation_error. The registration's bindings are in
// registration.cpp. Thin: the bindings check shapes and convert; the core validates values
// (std::invalid_argument naming the field becomes ValueError); work runs with the GIL released.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <vector>

#include "bayesgrasp/vision/camera.hpp"
#include "bayesgrasp/vision/registration.hpp"
#include "bayesgrasp/vision/segmentation.hpp"
#include "options.hpp"
#include "validate.hpp"
#include "vision_args.hpp"

namespace bayesgrasp::bind {

namespace py = pybind11;
using namespace bayesgrasp::vision;

void bind_registration(py::module_& m);

namespace {

std::vector<TriMesh> meshes_arg(const py::list& meshes) {
  std::vector<TriMesh> out;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const std::string name = "meshes[" + std::to_string(i) + "]";
    const py::tuple t = pair_at(meshes, i, name, "vertices, faces");
    out.push_back(mesh(t[0].cast<DArray>(), t[1].cast<IArray>(), name.c_str()));
  }
  return out;
}

py::array_t<std::int64_t> rows_out(const std::vector<int>& rows) {
  py::array_t<std::int64_t> out(static_cast<py::ssize_t>(rows.size()));
  std::copy(rows.begin(), rows.end(), out.mutable_data());
  return out;
}

void bind_camera_options(py::module_& m) {
  OptionClass<Intrinsics>(m, "Intrinsics", "Pinhole intrinsics in pixels (default: Kinect v1, 640 x 480).")
      .field("width", &Intrinsics::width, "int", "image columns")
      .field("height", &Intrinsics::height, "int", "image rows")
      .field("fx", &Intrinsics::fx, "float", "focal length along x, px")
      .field("fy", &Intrinsics::fy, "float", "focal length along y, px")
      .field("cx", &Intrinsics::cx, "float", "principal point column, px (pixel u's centre is at u)")
      .field("cy", &Intrinsics::cy, "float", "principal point row, px")
      .validator([](const Intrinsics& K) { validate(K); })
      .finish();

  OptionClass<Table>(m, "Table", "A table-top rectangle the camera sees (seen from both sides).")
      .field("enabled", &Table::enabled, "bool", "render the table")
      .field("z", &Table::z, "float", "m: its height")
      .field("center_x", &Table::center_x, "float", "m: its centre's x")
      .field("center_y", &Table::center_y, "float", "m: its centre's y")
      .field("half_x", &Table::half_x, "float", "m: half extent along x (inf allowed)")
      .field("half_y", &Table::half_y, "float", "m: half extent along y (inf allowed)")
      .validator([](const Table& t) { validate(t); })
      .finish();

  OptionClass<NoiseModel>(m, "NoiseModel", "Structured-light depth noise (defaults: Kinect v1), seeded.")
      .field("enabled", &NoiseModel::enabled, "bool", "False: a noise-free image")
      .field("sigma_a", &NoiseModel::sigma_a, "float", "m: axial sigma(z) = sigma_a + sigma_b (z - sigma_z0)^2")
      .field("sigma_b", &NoiseModel::sigma_b, "float", "1/m: see sigma_a")
      .field("sigma_z0", &NoiseModel::sigma_z0, "float", "m: see sigma_a")
      .field("baseline", &NoiseModel::baseline, "float", "m: projector-camera baseline (disparity f B / z)")
      .field("disparity_step", &NoiseModel::disparity_step, "float", "px: disparity quantum; 0 = off")
      .field("max_incidence", &NoiseModel::max_incidence, "float", "rad: steeper incidence is not measured")
      .field("edge_jump", &NoiseModel::edge_jump, "float", "m: a depth step this large is an edge")
      .field("edge_drop_prob", &NoiseModel::edge_drop_prob, "float", "probability an edge pixel is dropped")
      .field("min_depth", &NoiseModel::min_depth, "float", "m: nearer is not measured")
      .field("max_depth", &NoiseModel::max_depth, "float", "m: farther is not measured")
      .field("seed", &NoiseModel::seed, "int", "seed of the counter-based noise")
      .validator([](const NoiseModel& n) { validate(n); })
      .finish();
}

void bind_camera(py::module_& m) {
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
      [](const py::list& meshes, const DArray& pose, const Intrinsics& K, const Table& table,
         const NoiseModel& noise) {
        const Iso3 T = bind::pose(pose, "pose");
        const std::vector<TriMesh> ms = meshes_arg(meshes);
        RenderResult r;
        {
          py::gil_scoped_release release;
          r = render(K, T, ms, table, noise);
        }
        return py::make_tuple(r.depth, r.label);
      },
      py::arg("meshes"), py::arg("pose"), py::arg("intrinsics") = Intrinsics(), py::arg("table") = Table(),
      py::arg("noise") = NoiseModel(),
      "Ray-casts the meshes (list of (V (N,3), F (M,3)) in the world frame) and the table (if "
      "enabled) from camera pose `pose` (4x4 camera->world). Returns (depth (H,W) camera-frame z in "
      "metres, NaN where nothing is measured; label (H,W) int: mesh index, -2 table, -1 nothing, "
      "before noise).");

  m.def(
      "depth_to_points",
      [](const DArray& depth, const DArray& pose, const Intrinsics& K, bool world, bool organised) {
        if (depth.ndim() != 2) throw py::value_error("depth: expected shape (H, W), got " + shape_str(depth));
        const Iso3 T = bind::pose(pose, "pose");
        const DepthImage D = Eigen::Map<const DepthImage>(depth.data(), depth.shape(0), depth.shape(1));
        for (Eigen::Index i = 0; i < D.size(); ++i)
          if (std::isinf(D.data()[i])) throw py::value_error("depth: contains infinity (use NaN for missing)");
        Points P;
        {
          py::gil_scoped_release release;
          P = depth_to_points(K, D, T, world, organised);
        }
        return points_out(P);
      },
      py::arg("depth"), py::arg("pose"), py::arg("intrinsics") = Intrinsics(), py::arg("world") = true,
      py::arg("organised") = false,
      "Back-projects a depth image (H, W) (its size must be the intrinsics') to points: organised -> "
      "(H*W, 3) in pixel order with NaN rows for missing pixels, else (N, 3) valid points only; world "
      "frame (via pose) or camera frame.");
}

void bind_segmentation(py::module_& m) {
  OptionClass<SegmentationOptions>(m, "SegmentationOptions", "Table-top segmentation: plane, heights, clusters.")
      .field("plane_threshold", &SegmentationOptions::plane_threshold, "float", "m: plane RANSAC inlier distance")
      .field("plane_iterations", &SegmentationOptions::plane_iterations, "int", "plane RANSAC iterations")
      .field("min_height", &SegmentationOptions::min_height, "float", "m: kept points are at least this far above")
      .field("max_height", &SegmentationOptions::max_height, "float", "m: ... and at most this far")
      .field("cluster_tolerance", &SegmentationOptions::cluster_tolerance, "float", "m: Euclidean clustering distance")
      .field("min_cluster_size", &SegmentationOptions::min_cluster_size, "int", "smaller clusters are dropped")
      .field("max_cluster_size", &SegmentationOptions::max_cluster_size, "int", "larger clusters are dropped")
      .field("up", &SegmentationOptions::up, "ndarray (3,)", "the plane normal is oriented along it")
      .validator([](const SegmentationOptions& o) { validate(o); })
      .finish();

  py::class_<SegmentationResult>(m, "SegmentationResult", "The table plane and the objects on it.")
      .def_property_readonly("plane", [](const SegmentationResult& r) { return Eigen::Vector4d(r.plane); },
                             "plane : ndarray (4,)\n    (a, b, c, d): a x + b y + c z + d = 0, unit normal along up")
      .def_property_readonly("plane_inliers", [](const SegmentationResult& r) { return rows_out(r.plane_inliers); },
                             "plane_inliers : ndarray (n,) int64\n    rows of the input cloud on the plane")
      .def_property_readonly(
          "clusters",
          [](const SegmentationResult& r) {
            py::list out;
            for (const auto& c : r.clusters) out.append(rows_out(c));
            return out;
          },
          "clusters : list of ndarray int64\n    rows of the input cloud per object, largest first")
      .def_property_readonly(
          "cluster_points",
          [](const SegmentationResult& r) {
            py::list out;
            for (const auto& P : r.cluster_points) out.append(points_out(P));
            return out;
          },
          "cluster_points : list of ndarray (n_i, 3)\n    each object's points")
      .def("__repr__", [](const SegmentationResult& r) {
        return "SegmentationResult(plane_inliers=" + std::to_string(r.plane_inliers.size()) +
               ", clusters=" + std::to_string(r.clusters.size()) + ")";
      });

  m.def(
      "segment_table",
      [](const DArray& cloud, const SegmentationOptions& options) {
        const Points P = points_arg(cloud, "cloud", true);
        py::gil_scoped_release release;
        return segment_table(P, options);  // validates the options; errors name the field or the cloud
      },
      py::arg("cloud"), py::arg("options") = SegmentationOptions(),
      "Table-top segmentation of an (N, 3) cloud (NaN rows ignored): the dominant plane by RANSAC "
      "(normal oriented along options.up), points between min_height and max_height above it, "
      "Euclidean clusters (largest first). Returns a SegmentationResult.");
}

}  // namespace

void bind_vision(py::module_& m) {
  bind_camera_options(m);
  bind_camera(m);
  bind_segmentation(m);
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

// Bindings for cpp/bayesgrasp/physics: the Bullet lift test.
#include <string>

#include "bayesgrasp/physics/lift_test.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace {

// The hand: a path to a hand JSON file (str or os.PathLike), or a HandModel object if the
// hand bindings register one.
HandModel hand_arg(const py::handle& hand) {
  const py::module_ os = py::module_::import("os");
  if (py::isinstance<py::str>(hand) || py::isinstance(hand, os.attr("PathLike"))) {
    const std::string path = py::str(os.attr("fspath")(hand));
    try {
      return HandModel::from_file(path);
    } catch (const std::invalid_argument& e) {
      throw py::value_error(std::string("hand: ") + e.what());
    }
  }
  try {
    return hand.cast<HandModel>();
  } catch (const py::cast_error&) {
    throw py::type_error("hand: expected a path to a hand JSON file or a HandModel, got " +
                         std::string(py::str(py::type::of(hand).attr("__name__"))));
  }
}

std::string shape_name(LiftOptions::Shape s) {
  switch (s) {
    case LiftOptions::Shape::Auto: return "auto";
    case LiftOptions::Shape::ConvexHull: return "hull";
    case LiftOptions::Shape::Tetrahedra: return "tetrahedra";
    case LiftOptions::Shape::Decomposition: return "decomposition";
  }
  return "auto";
}

LiftOptions::Shape shape_from(const std::string& s) {
  if (s == "auto") return LiftOptions::Shape::Auto;
  if (s == "hull") return LiftOptions::Shape::ConvexHull;
  if (s == "tetrahedra") return LiftOptions::Shape::Tetrahedra;
  if (s == "decomposition") return LiftOptions::Shape::Decomposition;
  throw py::value_error("shape: expected 'auto', 'hull', 'tetrahedra' or 'decomposition', got '" + s + "'");
}

py::dict result_dict(const LiftResult& r) {
  py::dict d;
  d["lifted"] = r.lifted;
  d["displacement"] = r.displacement;
  d["rotation"] = r.rotation;
  d["squeeze_displacement"] = r.squeeze_displacement;
  d["height_gain"] = r.height_gain;
  d["finite"] = r.finite;
  d["steps"] = r.steps;
  d["tetrahedra"] = r.tetrahedra;
  d["shape"] = shape_name(r.shape);
  return d;
}

// std::invalid_argument from the core already becomes ValueError (pybind11's default
// translation); its messages name the argument.
// convex_pieces: None or a sequence of (K, 3) float arrays (K >= 4, finite).
std::vector<Eigen::MatrixX3d> pieces_arg(const py::object& pieces) {
  std::vector<Eigen::MatrixX3d> out;
  if (pieces.is_none()) return out;
  if (py::isinstance<py::str>(pieces) || !py::isinstance<py::sequence>(pieces))
    throw py::value_error("convex_pieces: expected None or a sequence of (K, 3) arrays");
  const py::sequence seq = pieces.cast<py::sequence>();
  for (size_t i = 0; i < seq.size(); ++i) {
    const std::string name = "convex_pieces[" + std::to_string(i) + "]";
    DArray a;
    try {
      a = seq[i].cast<DArray>();
    } catch (const py::cast_error&) {
      throw py::value_error(name + ": expected a (K, 3) float array");
    }
    const RowMatrixXd m = matrix(a, name.c_str(), 3);
    if (m.rows() < 4) throw py::value_error(name + ": needs at least 4 points, got " + std::to_string(m.rows()));
    out.emplace_back(m);
  }
  return out;
}

std::unique_ptr<LiftTester> make_tester(const py::handle& hand, const DArray& vertices, const IArray& faces,
                                        const LiftOptions& options, const py::object& convex_pieces) {
  const HandModel h = hand_arg(hand);
  const TriMesh mesh = bind::mesh(vertices, faces, "object");
  const std::vector<Eigen::MatrixX3d> pieces = pieces_arg(convex_pieces);
  py::gil_scoped_release release;  // the tetrahedra's ray casts take a while on big meshes
  return std::make_unique<LiftTester>(h, mesh, options, pieces);
}

}  // namespace

void bind_physics(py::module_& m) {
  py::class_<LiftOptions>(m, "LiftOptions", R"doc(Options of the lift test (SI units). See ``lift_test``.)doc")
      .def(py::init<>())
      .def_readwrite("mu", &LiftOptions::mu, "friction coefficient hand-object")
      .def_readwrite("table_mu", &LiftOptions::table_mu, "friction coefficient object-table")
      .def_readwrite("density", &LiftOptions::density, "object density, kg/m^3 (mass from the mesh)")
      .def_readwrite("time_step", &LiftOptions::time_step, "fixed time step, s (default 1/480)")
      .def_readwrite("solver_iterations", &LiftOptions::solver_iterations)
      .def_readwrite("squeeze_time", &LiftOptions::squeeze_time, "s, palm still while the fingers tighten")
      .def_readwrite("lift_height", &LiftOptions::lift_height, "m the palm rises (default 0.1)")
      .def_readwrite("lift_time", &LiftOptions::lift_time, "s")
      .def_readwrite("shake_amplitude", &LiftOptions::shake_amplitude, "m")
      .def_readwrite("shake_frequency", &LiftOptions::shake_frequency, "Hz")
      .def_readwrite("shake_time", &LiftOptions::shake_time, "s")
      .def_readwrite("hold_time", &LiftOptions::hold_time, "s")
      .def_readwrite("finger_torque", &LiftOptions::finger_torque, "N m, joint motor limit")
      .def_readwrite("closing_speed", &LiftOptions::closing_speed, "rad/s, joint motor target")
      .def_readwrite("squeeze_travel", &LiftOptions::squeeze_travel, "rad a joint may close beyond its angle")
      .def_readwrite("link_mass", &LiftOptions::link_mass, "kg per phalanx")
      .def_readwrite("success_distance", &LiftOptions::success_distance, "m (default 0.02)")
      .def_readwrite("table", &LiftOptions::table, "table plane at z = 0 present")
      .def_property(
          "shape", [](const LiftOptions& o) { return shape_name(o.shape); },
          [](LiftOptions& o, const std::string& s) { o.shape = shape_from(s); },
          "object collision shape: 'auto', 'hull', 'tetrahedra' or 'decomposition' (needs convex pieces)")
      .def_readwrite("tet_depth", &LiftOptions::tet_depth, "m, depth of the tetrahedra skin")
      .def_readwrite("margin", &LiftOptions::margin, "m, collision margin")
      .def_readwrite("skip_separated_pairs", &LiftOptions::skip_separated_pairs,
                     "skip Bullet's narrowphase for shape pairs proven apart (same results, faster)");

  py::class_<LiftTester>(m, "LiftTester", R"doc(Lift tests of one object with one hand (see ``lift_test``).

Args:
    hand: path to a hand JSON file (or a HandModel).
    vertices: (N, 3) object vertices in the world frame (m).
    faces: (M, 3) int triangles, counter-clockwise seen from outside.
    options: LiftOptions (defaults if None).
    convex_pieces: None or a list of (K, 3) point arrays in the world frame, an approximate
        convex decomposition of the object (each piece's convex hull is used): needed by
        shape 'decomposition', used by 'auto' for concave objects instead of the tetrahedra.)doc")
      .def(py::init([](const py::handle& hand, const DArray& vertices, const IArray& faces, const py::object& options,
                       const py::object& convex_pieces) {
             const LiftOptions o = options.is_none() ? LiftOptions{} : options.cast<LiftOptions>();
             return make_tester(hand, vertices, faces, o, convex_pieces);
           }),
           py::arg("hand"), py::arg("vertices"), py::arg("faces"), py::arg("options") = py::none(),
           py::arg("convex_pieces") = py::none())
      .def_property_readonly("mass", [](const LiftTester& t) { return t.mass_properties().mass; }, "object mass, kg")
      .def_property_readonly("com", [](const LiftTester& t) { return Eigen::Vector3d(t.mass_properties().com); },
                             "object centre of mass (world)")
      .def_property_readonly("shape", [](const LiftTester& t) { return shape_name(t.shape()); },
                             "collision shape prepared: 'hull', 'tetrahedra' or 'decomposition'")
      .def_property_readonly("concave", &LiftTester::concave,
                             "the object's hull volume is more than 5% above its volume")
      .def_property_readonly("num_pieces", &LiftTester::num_pieces, "convex pieces kept (0 without a decomposition)")
      .def(
          "run",
          [](const LiftTester& t, const DArray& hand_pose, const DArray& joints) {
            const Iso3 T = pose(hand_pose, "hand_pose");
            const Eigen::VectorXd q = vector(joints, "joints");
            LiftResult r;
            {
              py::gil_scoped_release release;
              r = t.run(T, q);
            }
            return result_dict(r);
          },
          py::arg("hand_pose"), py::arg("joints"),
          R"doc(One lift test. hand_pose: (4, 4) world pose of the hand; joints: (J,) closed joint
angles (HandModel layout). Returns a dict: lifted, displacement (m), rotation (rad),
squeeze_displacement (m), height_gain (m), finite, steps, tetrahedra (the object used the
tetrahedra shape), shape (the shape used: 'hull', 'tetrahedra' or 'decomposition').)doc")
      .def(
          "run_batch",
          [](const LiftTester& t, const DArray& hand_poses, const DArray& joints, int threads) {
            if (hand_poses.ndim() != 3 || hand_poses.shape(1) != 4 || hand_poses.shape(2) != 4)
              throw py::value_error("hand_poses: expected shape (N, 4, 4), got " + shape_str(hand_poses));
            const RowMatrixXd J = matrix(joints, "joints", -1, true);
            const py::ssize_t n = hand_poses.shape(0);
            if (J.rows() != n)
              throw py::value_error("joints: expected " + std::to_string(n) + " rows (one per pose), got " +
                                    std::to_string(J.rows()));
            std::vector<Iso3> poses;
            poses.reserve(static_cast<size_t>(n));
            for (py::ssize_t i = 0; i < n; ++i) {
              Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> M(hand_poses.data() + 16 * i);
              try {
                poses.push_back(pose_from_matrix(M));
              } catch (const std::invalid_argument& e) {
                throw py::value_error("hand_poses[" + std::to_string(i) + "]: " + e.what());
              }
            }
            std::vector<LiftResult> rs;
            {
              py::gil_scoped_release release;
              rs = t.run_batch(poses, J, threads);
            }
            py::array_t<bool> lifted(n);
            py::array_t<double> disp(n), rot(n), gain(n);
            for (py::ssize_t i = 0; i < n; ++i) {
              const LiftResult& r = rs[static_cast<size_t>(i)];
              lifted.mutable_data()[i] = r.lifted;
              disp.mutable_data()[i] = r.displacement;
              rot.mutable_data()[i] = r.rotation;
              gain.mutable_data()[i] = r.height_gain;
            }
            py::list shapes;
            for (const LiftResult& r : rs) shapes.append(shape_name(r.shape));
            py::dict d;
            d["shape"] = shapes;
            d["lifted"] = lifted;
            d["displacement"] = disp;
            d["rotation"] = rot;
            d["height_gain"] = gain;
            return d;
          },
          py::arg("hand_poses"), py::arg("joints"), py::arg("threads") = 1,
          R"doc(N lift tests in ``threads`` threads (<= 0: all cores), each with its own Bullet
world; GIL released. hand_poses: (N, 4, 4); joints: (N, J). Returns a dict of (N,) arrays:
lifted, displacement, rotation, height_gain - equal to ``run`` one by one - and shape (list
of the shapes used).)doc");
}

}  // namespace bayesgrasp::bind

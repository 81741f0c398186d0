// Bindings for cpp/bayesgrasp/physics: the Bullet lift test.
#include <string>
#include <pybind11/stl.h>

#include "bayesgrasp/physics/lift_test.hpp"
#include "options.hpp"
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

/// The results of run_batch, in input order.
struct LiftBatch {
  std::vector<LiftResult> results;
};

// convex_pieces: None or a sequence of (K, 3) float arrays (the core checks K >= 4 and the volume).
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
    out.emplace_back(matrix(a, name.c_str(), 3, true));
  }
  return out;
}

void bind_options(py::module_& m) {
  OptionClass<LiftOptions>(m, "LiftOptions", R"doc(Options of the lift test (SI units). See ``lift_test``.)doc")
      .field("mu", &LiftOptions::mu, "float", "Friction coefficient hand-object (>= 0).")
      .field("table_mu", &LiftOptions::table_mu, "float", "Friction coefficient object-table (>= 0).")
      .field("density", &LiftOptions::density, "float", "Object density, kg/m^3 (mass from the mesh).")
      .field("time_step", &LiftOptions::time_step, "float", "Fixed time step, s (default 1/480).")
      .field("solver_iterations", &LiftOptions::solver_iterations, "int",
             "Bullet's constraint solver iterations per step (>= 1, default 100).")
      .field("solver_residual", &LiftOptions::solver_residual, "float",
             "a step's solver iterations end once Bullet's least-squares residual is below this (its units); 0 "
             "(default) runs them all.")
      .field("warmstart_factor", &LiftOptions::warmstart_factor, "float",
             "share of a contact's impulses of the last step each step starts from (Bullet's warm start, 0..1; "
             "default 0.85).")
      .field("friction_direction_caching", &LiftOptions::friction_direction_caching, "bool",
             "keep each contact's two friction directions from step to step, so its friction impulses warm-start "
             "too (default False).")
      .field("squeeze_time", &LiftOptions::squeeze_time, "float", "s, the palm still while the fingers tighten.")
      .field("lift_height", &LiftOptions::lift_height, "float", "m the palm rises.")
      .field("lift_time", &LiftOptions::lift_time, "float", "s the rise takes.")
      .field("shake_amplitude", &LiftOptions::shake_amplitude, "float", "m, per axis.")
      .field("shake_frequency", &LiftOptions::shake_frequency, "float", "Hz, of the shake.")
      .field("shake_time", &LiftOptions::shake_time, "float", "s of shaking.")
      .field("hold_time", &LiftOptions::hold_time, "float", "s held still at the end.")
      .field("finger_torque", &LiftOptions::finger_torque, "float",
             "N m; > 0: the torque limit of each finger's one motor at every joint it drives (the proximal, the distal "
             "after breakaway; coupled phalanges load the same motor); 0 (default): each joint's torque from the hand "
             "file (torque_nm, the hand's published strength).")
      .field("closing_speed", &LiftOptions::closing_speed, "float",
             "rad/s, the finger motors' target velocity (closing).")
      .field("drive_inertia", &LiftOptions::drive_inertia, "float",
             "kg m^2 added to each phalanx about its joint axis (the drive's reflected rotor inertia).")
      .field("worm_backlash", &LiftOptions::worm_backlash, "float",
             "rad a driven or locked finger joint may open below the largest angle it reached (the worm drive's "
             "backlash; 0: a rigid ratchet).")
      .field("link_mass", &LiftOptions::link_mass, "float", "kg per phalanx.")
      .field("success_distance", &LiftOptions::success_distance, "float",
             "m; lifted = the object rose at least lift_height minus this, and moved less than this in the palm frame "
             "from the end of the lift to the end.")
      .field("table", &LiftOptions::table, "bool", "A table plane at z = 0.")
      .property(
          "shape", [](const LiftOptions& o) { return shape_name(o.shape); },
          [](LiftOptions& o, const std::string& s) { o.shape = shape_from(s); }, "str",
          "Object collision shape: 'auto', 'hull', 'tetrahedra' or 'decomposition' (needs convex pieces).")
      .field("tet_depth", &LiftOptions::tet_depth, "float", "m, depth of the tetrahedra skin.")
      .field("margin", &LiftOptions::margin, "float", "m, collision margin of every shape.")
      .field("skip_separated_pairs", &LiftOptions::skip_separated_pairs, "bool",
             "Skip Bullet's narrowphase for shape pairs proven apart (same results, faster).")
      .validator([](const LiftOptions& o) { validate(o); })
      .finish();
}

void bind_trace(py::module_& m) {
  using T = LiftTrace;
  auto ints = [](const std::vector<LiftContact>& cs, int LiftContact::*f) {
    Eigen::VectorXi v(static_cast<Eigen::Index>(cs.size()));
    for (size_t i = 0; i < cs.size(); ++i) v[static_cast<Eigen::Index>(i)] = cs[i].*f;
    return v;
  };
  auto vecs = [](const std::vector<LiftContact>& cs, Vec3 LiftContact::*f) {
    RowMatrixXd v(static_cast<Eigen::Index>(cs.size()), 3);
    for (size_t i = 0; i < cs.size(); ++i) v.row(static_cast<Eigen::Index>(i)) = (cs[i].*f).transpose();
    return to_numpy(v);
  };
  auto rows = [](const auto& vs, Eigen::Index cols) {
    Eigen::Matrix<typename std::decay_t<decltype(vs[0])>::Scalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> M(
        static_cast<Eigen::Index>(vs.size()), cols);
    for (size_t i = 0; i < vs.size(); ++i) M.row(static_cast<Eigen::Index>(i)) = vs[i].transpose();
    return M;
  };
  py::class_<T, std::shared_ptr<T>>(m, "LiftTrace", R"doc(Per-step trace of one lift test (S samples: every
``every`` steps and the last step simulated; C contacts in all). Arrays are copies.)doc")
      .def_readonly("every", &T::every, "every : int\n    Steps between samples.")
      .def_readonly("link_names", &T::link_names, "link_names : list of str\n    The hand's link names.")
      .def_property_readonly("phase_ends", [](const T& t) { return Eigen::Vector3d(t.phase_ends); },
                             "phase_ends : numpy.ndarray (3,)\n    s, end of the squeeze, the lift and the shake.")
      .def_property_readonly("reference_pose", [](const T& t) { return to_numpy(t.reference_pose); },
                             "reference_pose : numpy.ndarray (4, 4)\n    The object (centre of mass, principal axes) in "
                             "the palm frame after the squeeze: the displacement's reference.")
      .def_property_readonly("time", [](const T& t) { return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(t.time.data(), static_cast<Eigen::Index>(t.time.size()))); },
                             "time : numpy.ndarray (S,)\n    s.")
      .def_property_readonly("object_pose", [](const T& t) { return to_numpy(t.object_pose); },
                             "object_pose : numpy.ndarray (S, 4, 4)\n    The object in the palm frame.")
      .def_property_readonly("joints", [rows](const T& t) {
                               return RowMatrixXd(rows(t.joints, t.joints.empty() ? 0 : t.joints[0].size())); },
                             "joints : numpy.ndarray (S, J)\n    Joint angles, rad (HandModel layout).")
      .def_property_readonly("driven", [rows](const T& t) {
                               return rows(t.driven, t.driven.empty() ? 0 : t.driven[0].size()); },
                             "driven : numpy.ndarray (S, F) int\n    The phalanx each finger's motor drives.")
      .def_property_readonly("contact_sample", [ints](const T& t) { return ints(t.contacts, &LiftContact::sample); },
                             "contact_sample : numpy.ndarray (C,) int\n    Sample index of each contact.")
      .def_property_readonly("contact_link", [ints](const T& t) { return ints(t.contacts, &LiftContact::link); },
                             "contact_link : numpy.ndarray (C,) int\n    Hand link index (0: palm and knuckles).")
      .def_property_readonly("contact_point", [vecs](const T& t) { return vecs(t.contacts, &LiftContact::point); },
                             "contact_point : numpy.ndarray (C, 3)\n    m, world frame, on the hand link.")
      .def_property_readonly("contact_normal", [vecs](const T& t) { return vecs(t.contacts, &LiftContact::normal); },
                             "contact_normal : numpy.ndarray (C, 3)\n    Unit, out of the object.")
      .def_property_readonly("contact_force",
                             [](const T& t) {
                               Eigen::VectorXd v(static_cast<Eigen::Index>(t.contacts.size()));
                               for (size_t i = 0; i < t.contacts.size(); ++i) v[static_cast<Eigen::Index>(i)] = t.contacts[i].force;
                               return v;
                             },
                             "contact_force : numpy.ndarray (C,)\n    N, normal force.");
}

void bind_results(py::module_& m) {
  using R = LiftResult;
  py::class_<R>(m, "LiftResult", "The outcome of one lift test.")
      .def_readonly("lifted", &R::lifted,
                    "lifted : bool\n    The object came up (height_gain >= lift_height - success_distance), held "
                    "through the shake and hold (hold_displacement < success_distance), and the simulation stayed "
                    "finite.")
      .def_readonly("displacement", &R::displacement,
                    "displacement : float\n    m, the object's centre of mass relative to the palm, end vs after "
                    "the squeeze.")
      .def_readonly("hold_displacement", &R::hold_displacement,
                    "hold_displacement : float\n    m, the object's centre of mass relative to the palm, end vs the "
                    "end of the lift (0 if the run stopped before).")
      .def_readonly("rotation", &R::rotation,
                    "rotation : float\n    rad, the object's rotation relative to the palm, end vs after the squeeze.")
      .def_readonly("squeeze_displacement", &R::squeeze_displacement,
                    "squeeze_displacement : float\n    m the squeeze itself moved the object (palm frame).")
      .def_readonly("height_gain", &R::height_gain,
                    "height_gain : float\n    m, world z of the object's centre of mass, end minus start.")
      .def_readonly("finite", &R::finite, "finite : bool\n    False if the simulation blew up.")
      .def_readonly("tetrahedra", &R::tetrahedra, "tetrahedra : bool\n    The object used the tetrahedra shape.")
      .def_property_readonly(
          "shape", [](const R& r) { return shape_name(r.shape); },
          "shape : str\n    The shape used: 'hull', 'tetrahedra' or 'decomposition'.")
      .def_readonly("steps", &R::steps, "steps : int\n    Time steps simulated (fewer when the object was lost early).")
      .def_readonly("skipped_queries", &R::skipped_queries,
                    "skipped_queries : int\n    Narrowphase queries skipped (skip_separated_pairs).")
      .def_property_readonly(
          "breakaway", [](const R& r) { return Eigen::VectorXi(r.breakaway); },
          "breakaway : numpy.ndarray (F,) int\n    Per finger, the phalanx its motor drives at the end (0: no "
          "breakaway; 1: the proximal locked, the distal driven).")
      .def_property_readonly(
          "trace", [](const R& r) -> py::object { return r.trace ? py::cast(r.trace) : py::none(); },
          "trace : LiftTrace or None\n    The per-step trace (run with trace_every > 0), else None.")
      .def("__repr__", [](const R& r) {
        return std::string("<LiftResult: ") + (r.lifted ? "lifted" : "dropped") + ", displacement " +
               std::to_string(r.displacement) + " m>";
      });

  using B = LiftBatch;
  auto view = [](auto member) {
    return [member](const py::object& self) {
      const B& b = self.cast<const B&>();
      return field_view(b.results.data(), b.results.size(), member, self);
    };
  };
  py::class_<B>(m, "LiftBatch", "N lift tests: each LiftResult field as an (N,) array (read-only views).")
      .def_property_readonly("lifted", view(&R::lifted), "lifted : numpy.ndarray (N,) bool")
      .def_property_readonly("displacement", view(&R::displacement), "displacement : numpy.ndarray (N,) float\n    m.")
      .def_property_readonly("hold_displacement", view(&R::hold_displacement),
                             "hold_displacement : numpy.ndarray (N,) float\n    m.")
      .def_property_readonly("rotation", view(&R::rotation), "rotation : numpy.ndarray (N,) float\n    rad.")
      .def_property_readonly("squeeze_displacement", view(&R::squeeze_displacement),
                             "squeeze_displacement : numpy.ndarray (N,) float\n    m.")
      .def_property_readonly("height_gain", view(&R::height_gain), "height_gain : numpy.ndarray (N,) float\n    m.")
      .def_property_readonly("finite", view(&R::finite), "finite : numpy.ndarray (N,) bool")
      .def_property_readonly("tetrahedra", view(&R::tetrahedra), "tetrahedra : numpy.ndarray (N,) bool")
      .def_property_readonly("steps", view(&R::steps), "steps : numpy.ndarray (N,) int32")
      .def_property_readonly("skipped_queries", view(&R::skipped_queries), "skipped_queries : numpy.ndarray (N,) int64")
      .def_property_readonly(
          "shape",
          [](const B& b) {
            py::list out;
            for (const R& r : b.results) out.append(shape_name(r.shape));
            return out;
          },
          "shape : list of str\n    The shape each test used.")
      .def("__len__", [](const B& b) { return b.results.size(); })
      .def("__getitem__", [](const B& b, py::ssize_t i) {
        const auto n = static_cast<py::ssize_t>(b.results.size());
        if (i < 0) i += n;
        if (i < 0 || i >= n) throw py::index_error("lift batch index out of range");
        return b.results[static_cast<size_t>(i)];
      });
}

std::unique_ptr<LiftTester> make_tester(const py::handle& hand, const DArray& vertices, const IArray& faces,
                                        const LiftOptions& options, const py::object& convex_pieces,
                                        const py::object& mass_properties) {
  const HandModel h = hand_arg(hand);
  const TriMesh mesh = bind::mesh(vertices, faces, "object");
  const std::vector<Eigen::MatrixX3d> pieces = pieces_arg(convex_pieces);
  std::optional<MassProperties> mass;
  if (!mass_properties.is_none()) {
    if (!py::isinstance<MassProperties>(mass_properties))
      throw py::type_error("mass_properties: expected None or a MassProperties");
    mass = mass_properties.cast<MassProperties>();
  }
  py::gil_scoped_release release;  // the tetrahedra's ray casts take a while on big meshes
  return std::make_unique<LiftTester>(h, mesh, options, pieces, mass);
}

}  // namespace

void bind_physics(py::module_& m) {
  bind_options(m);
  bind_trace(m);
  bind_results(m);
  py::class_<LiftTester>(m, "LiftTester", R"doc(Lift tests of one object with one hand (see ``lift_test``).

Args:
    hand: path to a hand JSON file (or a HandModel).
    vertices: (N, 3) object vertices in the world frame (m).
    faces: (M, 3) int triangles, counter-clockwise seen from outside.
    options: LiftOptions (defaults if None).
    convex_pieces: None or a list of (K, 3) point arrays in the world frame, an approximate
        convex decomposition of the object (each piece's convex hull is used): needed by
        shape 'decomposition', used by 'auto' for concave objects instead of the tetrahedra.
    mass_properties: None (the closed mesh's at options.density) or a MassProperties in the
        world frame (an open scan's, a weighed object's).)doc")
      .def(py::init([](const py::handle& hand, const DArray& vertices, const IArray& faces, const py::object& options,
                       const py::object& convex_pieces, const py::object& mass_properties) {
             const LiftOptions o = options.is_none() ? LiftOptions{} : options.cast<LiftOptions>();
             return make_tester(hand, vertices, faces, o, convex_pieces, mass_properties);
           }),
           py::arg("hand"), py::arg("vertices"), py::arg("faces"), py::arg("options") = py::none(),
           py::arg("convex_pieces") = py::none(), py::arg("mass_properties") = py::none())
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
          [](const LiftTester& t, const DArray& hand_pose, const DArray& joints, int trace_every) {
            const Iso3 T = pose(hand_pose, "hand_pose");
            const Eigen::VectorXd q = vector(joints, "joints");
            if (trace_every < 0) throw py::value_error("trace_every: must be >= 0, got " + std::to_string(trace_every));
            py::gil_scoped_release release;
            return t.run(T, q, trace_every);
          },
          py::arg("hand_pose"), py::arg("joints"), py::arg("trace_every") = 0,
          R"doc(One lift test. hand_pose: (4, 4) world pose of the hand; joints: (J,) closed joint
angles (HandModel layout); trace_every: record a LiftTrace every that many steps (0: none).
A LiftResult (its ``trace`` the LiftTrace or None).)doc")
      .def(
          "shapes",
          [](const LiftTester& t, const DArray& hand_poses, const DArray& joints) {
            const std::vector<Iso3> P = poses(hand_poses, "hand_poses");
            const RowMatrixXd J = matrix(joints, "joints", -1, true);
            std::vector<LiftOptions::Shape> s;
            {
              py::gil_scoped_release release;
              s = t.shapes(P, J);
            }
            py::list out;
            for (const LiftOptions::Shape x : s) out.append(shape_name(x));
            return out;
          },
          py::arg("hand_poses"), py::arg("joints"),
          R"doc(The shape each grasp's lift test would use ('hull', 'tetrahedra' or 'decomposition'),
without simulating: under 'auto' on a concave object the hull unless a hand link reaches into it.
hand_poses: (N, 4, 4); joints: (N, J). A list of str.)doc")
      .def(
          "run_batch",
          [](const LiftTester& t, const DArray& hand_poses, const DArray& joints, int threads) {
            const std::vector<Iso3> P = poses(hand_poses, "hand_poses");
            const RowMatrixXd J = matrix(joints, "joints", -1, true);
            py::gil_scoped_release release;
            return LiftBatch{t.run_batch(P, J, threads)};
          },
          py::arg("hand_poses"), py::arg("joints"), py::arg("threads") = 1,
          R"doc(N lift tests in ``threads`` threads (0 = all cores), each with its own Bullet world;
GIL released. hand_poses: (N, 4, 4); joints: (N, J). A LiftBatch, equal to ``run`` one by one.)doc");
}

}  // namespace bayesgrasp::bind

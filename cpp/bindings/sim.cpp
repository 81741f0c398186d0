// Bindings for cpp/bayesgrasp/sim: the grasp simulator (auto-grasp with breakaway, approaches
// and top grasps, batches with the GIL released). Options and results are bound classes; the results' array
// fields are read-only numpy views of the C++ results (no copies). Arguments are validated by
// the core (std::invalid_argument becomes ValueError).
#include <pybind11/stl.h>

#include <type_traits>

#include "bayesgrasp/sim/grasp_simulator.hpp"
#include "options.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace {

/// A run of contacts inside a bound result (`owner` keeps the memory alive).
struct ContactArrays {
  py::object owner;
  const Contact* first = nullptr;
  size_t count = 0;
};

/// A batch's contacts with the grasp each belongs to.
struct BatchContactArrays : ContactArrays {
  const std::vector<int64_t>* offsets = nullptr;
};

constexpr py::ssize_t kDouble = sizeof(double), kInt = sizeof(int);

ContactArrays contacts_of(const py::object& owner, const Contacts& cs) { return {owner, cs.data(), cs.size()}; }

py::array flags_view(const uint8_t* data, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides,
                     py::handle owner) {
  return readonly_view(py::dtype::of<bool>(), shape, strides, data, owner);
}

py::array flags_view(const std::vector<uint8_t>& flags, py::handle owner) {
  return flags_view(flags.data(), {static_cast<py::ssize_t>(flags.size())}, {1}, owner);
}

template <class M>
py::array flag_matrix_view(const M& m, py::handle owner) {
  return flags_view(m.data(), {m.rows(), m.cols()}, {m.cols(), 1}, owner);
}

void bind_contacts(py::module_& m) {
  // a property returning the view of one Contact member
  const auto column = [](auto member) {
    return [member](const ContactArrays& c) {
      if constexpr (std::is_same_v<decltype(c.first->*member), const Vec3&>)
        return vec3_field_view(c.first, c.count, member, c.owner);
      else
        return field_view(c.first, c.count, member, c.owner);
    };
  };
  py::class_<ContactArrays>(m, "Contacts", R"doc(Contacts of a simulated grasp, as arrays (K rows).

Normals are the object's outward surface normals (+z for the table): what bayesgrasp.quality
consumes. Read-only views of the result they belong to.)doc")
      .def_property_readonly("point", column(&Contact::point),
                             "point : numpy.ndarray (K, 3) float\n    Contact point on the object's (or the table's) "
                             "surface, world frame (m).")
      .def_property_readonly("normal", column(&Contact::normal),
                             "normal : numpy.ndarray (K, 3) float\n    Outward unit normal of the object (+z for the "
                             "table), world frame.")
      .def_property_readonly("link", column(&Contact::link),
                             "link : numpy.ndarray (K,) int32\n    Index of the hand link in contact (0 = palm).")
      .def_property_readonly("penetration", column(&Contact::penetration),
                             "penetration : numpy.ndarray (K,) float\n    Depth of overlap (m, >= 0; 0 when touching "
                             "within the tolerance).")
      .def_property_readonly("on_table", column(&Contact::on_table),
                             "on_table : numpy.ndarray (K,) bool\n    The contact is with the table, not the object.")
      .def_property_readonly("triangle", column(&Contact::triangle),
                             "triangle : numpy.ndarray (K,) int32\n    Index of the object's triangle nearest to the "
                             "link (a row of the simulator's faces; -1 for the table).")
      .def("__len__", [](const ContactArrays& c) { return c.count; });

  py::class_<BatchContactArrays, ContactArrays>(m, "BatchContacts", R"doc(The contacts of a batch of grasps,
concatenated: grasp i's contacts are rows offsets[i]:offsets[i+1].)doc")
      .def_property_readonly(
          "grasp",
          [](const BatchContactArrays& c) {
            py::array_t<int64_t> g(static_cast<py::ssize_t>(c.count));
            auto o = g.mutable_unchecked<1>();
            for (size_t i = 0; i + 1 < c.offsets->size(); ++i)
              for (int64_t k = (*c.offsets)[i]; k < (*c.offsets)[i + 1]; ++k) o(k) = static_cast<int64_t>(i);
            return g;
          },
          "grasp : numpy.ndarray (K,) int64\n    Index of the grasp each contact belongs to (a new array).")
      .def_property_readonly(
          "offsets",
          [](const BatchContactArrays& c) {
            return readonly_view(py::dtype::of<int64_t>(), {static_cast<py::ssize_t>(c.offsets->size())},
                                 {static_cast<py::ssize_t>(sizeof(int64_t))}, c.offsets->data(), c.owner);
          },
          "offsets : numpy.ndarray (N + 1,) int64\n    Grasp i's contacts are rows offsets[i]:offsets[i+1].");
}

void bind_options(py::module_& m) {
  OptionClass<SimOptions> o(m, "SimOptions", R"doc(Options of the grasp simulator (SI units).

The defaults are what every caller uses; the others exist for tests and benchmarks.)doc");
  py::enum_<SimOptions::Bv>(o.cls(), "BoundingVolume", "FCL bounding volume of the object's BVH.")
      .value("OBBRSS", SimOptions::Bv::OBBRSS)
      .value("RSS", SimOptions::Bv::RSS);
  py::enum_<SimOptions::LinkGeometry>(o.cls(), "LinkGeometry", "Link geometry of the FCL distance queries.")
      .value("Segments", SimOptions::LinkGeometry::Segments)
      .value("Primitives", SimOptions::LinkGeometry::Primitives)
      .value("Meshes", SimOptions::LinkGeometry::Meshes);
  o.field("table", &SimOptions::table, "bool", "An infinite table plane at z = 0.")
      .field("contact_tolerance", &SimOptions::contact_tolerance, "float",
             "A link touches when closer than this (m, > 0).")
      .field("rel_err", &SimOptions::rel_err, "float",
             "Error allowance of the advancing distance queries, relative to the link's lower bound on its distance (in"
             " [0, 1); 0 = exact).")
      .field("tie_tolerance", &SimOptions::tie_tolerance, "float",
             "Triangle pairs whose distances to a link differ by less than this count as tied; a query keeps the first "
             "(m, in [0, contact_tolerance / 10); 0 = FCL's own traversal).")
      .field("box_skip", &SimOptions::box_skip, "float",
             "Links whose lower bound on the object distance exceeds this use the bound instead of an FCL query (m, > "
             "contact_tolerance).")
      .field("bv", &SimOptions::bv, "SimOptions.BoundingVolume", "The object's bounding volumes.")
      .field("links", &SimOptions::links, "SimOptions.LinkGeometry",
             "Segments (capsule axes as sliver triangles, boxes as meshes), Primitives (FCL capsules and boxes) or "
             "Meshes (tessellated capsules).")
      .field("max_iterations", &SimOptions::max_iterations, "int",
             "Advancement steps per finger and per approach (a safety net, >= 1).")
      .field("table_clearance", &SimOptions::table_clearance, "float",
             "Approaches along -z (top grasps) with a table keep the fingers' closing sweep at least this far above it "
             "(m); negative: stop at the first contact.")
      .field("prune_queries", &SimOptions::prune_queries, "bool",
             "Skip FCL queries whose answer cannot change the result (same grasps up to round-off).")
      .validator([](const SimOptions& x) { validate(x); })
      .finish();
}

py::tuple object_contacts(const Contacts& cs) {
  std::vector<Vec3> p, n;
  for (const Contact& c : cs)
    if (!c.on_table) p.push_back(c.point), n.push_back(c.normal);
  RowMatrixXd P(p.size(), 3), N(n.size(), 3);
  for (size_t k = 0; k < p.size(); ++k) P.row(k) = p[k].transpose(), N.row(k) = n[k].transpose();
  return py::make_tuple(to_numpy(P), to_numpy(N));
}

void bind_result(py::module_& m) {
  using R = GraspResult;
  py::class_<R>(m, "GraspResult", "One simulated grasp (read-only; array fields are views).")
      .def_property_readonly(
          "joint_angles",
          [](const py::object& self) {
            const R& r = self.cast<const R&>();
            return readonly_view(py::dtype::of<double>(), {r.joints.size()}, {kDouble}, r.joints.data(), self);
          },
          "joint_angles : numpy.ndarray (J,) float\n    Closed joint angles (rad), hand layout.")
      .def_property_readonly(
          "contacts", [](const py::object& self) { return contacts_of(self, self.cast<const R&>().contacts); },
          "contacts : Contacts\n    At most one object and one table contact per link.")
      .def_property_readonly(
          "link_contact", [](const py::object& self) { return flags_view(self.cast<const R&>().link_contact, self); },
          "link_contact : numpy.ndarray (L,) bool\n    Per link: it touches the object.")
      .def_property_readonly(
          "table_contact", [](const py::object& self) { return flags_view(self.cast<const R&>().table_contact, self); },
          "table_contact : numpy.ndarray (L,) bool\n    Per link: it touches the table.")
      .def_readonly("collision_at_start", &R::collision_at_start,
                    "collision_at_start : bool\n    The open hand penetrated the object or the table (the fingers "
                    "then stay open and there are no contacts).")
      .def_readonly("stopped_by_table", &R::stopped_by_table,
                    "stopped_by_table : bool\n    The approach stopped on the table without touching the object "
                    "(False for closing at a given pose).")
      .def_property_readonly(
          "hand_pose", [](const py::object& self) { return pose_view(self.cast<const R&>().hand_pose, self); },
          "hand_pose : numpy.ndarray (4, 4) float\n    World pose of the hand while closing (where an approach "
          "stopped, after the stand-off).")
      .def_readonly("distance_queries", &R::distance_queries, "distance_queries : int\n    FCL distance calls spent.")
      .def_readonly("iterations", &R::iterations, "iterations : int\n    Advancement steps (fingers and approach).")
      .def_property_readonly(
          "num_contacts", [](const R& r) { return r.contacts.size(); }, "num_contacts : int\n    Number of contacts.")
      .def(
          "object_contacts", [](const R& r) { return object_contacts(r.contacts); },
          "(points, normals): (K, 3) arrays of the contacts with the object (not the table), for quality metrics.")
      .def("__repr__", [](const R& r) {
        return "<GraspResult: " + std::to_string(r.contacts.size()) + " contacts" +
               (r.collision_at_start ? ", collision at start>" : ">");
      });

}

void bind_batch(py::module_& m) {
  using B = GraspBatch;
  py::class_<B>(m, "GraspBatch", R"doc(N simulated grasps as arrays (row i = grasp i; read-only views).)doc")
      .def_readonly("num_grasps", &B::num_grasps, "num_grasps : int\n    N.")
      .def_property_readonly(
          "joint_angles",
          [](const py::object& self) {
            const B& b = self.cast<const B&>();
            return readonly_view(py::dtype::of<double>(), {b.joints.rows(), b.joints.cols()},
                                 {kDouble * b.joints.cols(), kDouble},
                                 b.joints.data(), self);
          },
          "joint_angles : numpy.ndarray (N, J) float\n    Closed joint angles (rad), hand layout.")
      .def_property_readonly(
          "contacts",
          [](const py::object& self) {
            const B& b = self.cast<const B&>();
            BatchContactArrays c;
            static_cast<ContactArrays&>(c) = contacts_of(self, b.contacts);
            c.offsets = &b.offsets;
            return c;
          },
          "contacts : BatchContacts\n    All contacts, concatenated; see BatchContacts.offsets.")
      .def(
          "grasp_contacts",
          [](const py::object& self, int i) {
            const B& b = self.cast<const B&>();
            if (i < 0 || i >= b.num_grasps)
              throw py::index_error("i: must lie in [0, " + std::to_string(b.num_grasps) + ")");
            return ContactArrays{self, b.contacts.data() + b.offsets[i], static_cast<size_t>(b.offsets[i + 1] - b.offsets[i])};
          },
          py::arg("i"), "The contacts of grasp i (views).")
      .def_property_readonly(
          "link_contact", [](const py::object& self) { return flag_matrix_view(self.cast<const B&>().link_contact, self); },
          "link_contact : numpy.ndarray (N, L) bool\n    Per grasp and link: it touches the object.")
      .def_property_readonly(
          "table_contact", [](const py::object& self) { return flag_matrix_view(self.cast<const B&>().table_contact, self); },
          "table_contact : numpy.ndarray (N, L) bool\n    Per grasp and link: it touches the table.")
      .def_property_readonly(
          "collision_at_start",
          [](const py::object& self) { return flags_view(self.cast<const B&>().collision_at_start, self); },
          "collision_at_start : numpy.ndarray (N,) bool\n    The open hand penetrated the object or the table.")
      .def_property_readonly(
          "stopped_by_table",
          [](const py::object& self) { return flags_view(self.cast<const B&>().stopped_by_table, self); },
          "stopped_by_table : numpy.ndarray (N,) bool\n    The approach stopped on the table without touching "
          "the object.")
      .def_property_readonly(
          "hand_pose",
          [](const py::object& self) {
            const B& b = self.cast<const B&>();
            return poses_view(b.hand_poses.data(), b.hand_poses.size(), self);
          },
          "hand_pose : numpy.ndarray (N, 4, 4) float\n    World poses of the hand while closing (where the "
          "approaches stopped, after the stand-off).")
      .def_property_readonly(
          "distance_queries",
          [](const py::object& self) {
            const B& b = self.cast<const B&>();
            return readonly_view(py::dtype::of<int>(), {static_cast<py::ssize_t>(b.distance_queries.size())},
                                 {kInt}, b.distance_queries.data(), self);
          },
          "distance_queries : numpy.ndarray (N,) int32\n    FCL distance calls per grasp.")
      .def("__len__", [](const B& b) { return b.num_grasps; });
}

/// A number or an (N,) array as N values (`name` in errors).
std::vector<double> values(const py::object& x, const char* name, size_t n) {
  if (py::isinstance<py::float_>(x) || py::isinstance<py::int_>(x)) return std::vector<double>(n, x.cast<double>());
  const Eigen::VectorXd v = vector(x.cast<DArray>(), name);
  if (static_cast<size_t>(v.size()) != n)
    throw py::value_error(std::string(name) + ": need a number or one per approach (" + std::to_string(n) + "), got " +
                          std::to_string(v.size()));
  return std::vector<double>(v.data(), v.data() + v.size());
}

/// N approaches from (N, 3) directions and targets and N rolls (not checked: the core checks them).
std::vector<ApproachSpec> approaches(const DArray& directions, const DArray& targets, const py::object& rolls) {
  const auto rows = [](const DArray& a, const char* name) {
    if (a.ndim() != 2 || a.shape(1) != 3)
      throw py::value_error(std::string(name) + ": expected shape (N, 3), got " + shape_str(a));
    return Eigen::Map<const RowMatrixXd>(a.data(), a.shape(0), 3);
  };
  const auto D = rows(directions, "directions");
  const auto P = rows(targets, "targets");
  if (P.rows() != D.rows())
    throw py::value_error("targets: need one per direction (" + std::to_string(D.rows()) + "), got " +
                          std::to_string(P.rows()));
  const std::vector<double> R = values(rolls, "rolls", static_cast<size_t>(D.rows()));
  std::vector<ApproachSpec> out(static_cast<size_t>(D.rows()));
  for (size_t i = 0; i < out.size(); ++i) out[i] = {D.row(i).transpose(), R[i], P.row(i).transpose()};
  return out;
}

/// The approach calls (GIL released).
void def_approaches(py::class_<GraspSimulator>& sim) {
  sim.def(
         "approach",
         [](const GraspSimulator& s, const DArray& direction, const DArray& target, double roll, double spread,
            double standoff) {
           const ApproachSpec a{vec3(direction, "direction"), roll, vec3(target, "target")};
           py::gil_scoped_release release;
           return s.approach(a, spread, standoff);
         },
         py::arg("direction"), py::arg("target"), py::arg("roll"), py::arg("spread"), py::arg("standoff") = 0.0,
         R"doc(Approach, then auto-grasp (world frame; a GraspResult).

The open hand, oriented by `direction` (its +z; normalised) and `roll` (rad, right-handed
about -direction: the palm-down top-grasp hand at yaw = roll tilted by the smallest rotation
taking -z onto the direction; see Hand.approach_pose), starts on the line through `target`
along the direction, clear of the object and the table, moves along it until a link is
within the contact tolerance of the object or of the table (when moving down onto it), backs
off by `standoff` (m) and closes. stopped_by_table says the table stopped it;
collision_at_start that the open hand started in the table (no grasp). ValueError naming
`direction` (zero or not finite), `roll`, `target` (not finite, below the table), `spread`,
`standoff`.)doc")
      .def(
          "approach_batch",
          [](const GraspSimulator& s, const DArray& directions, const DArray& targets, const py::object& rolls,
             double spread, double standoff, int threads) {
            const std::vector<ApproachSpec> a = approaches(directions, targets, rolls);
            py::gil_scoped_release release;
            return s.approach_batch(a, spread, standoff, threads);
          },
          py::arg("directions"), py::arg("targets"), py::arg("rolls"), py::arg("spread"),
          py::arg("standoff") = 0.0, py::arg("threads") = 1,
          R"doc(N approaches: directions and targets (N, 3), rolls a number or (N,), in `threads` C++
threads (0 = all cores), without the GIL; a GraspBatch (errors name the entry, e.g.
`directions[2]`).)doc");
}

/// The batch calls (GIL released; threads: 0 = all cores).
void def_batches(py::class_<GraspSimulator>& sim) {
  sim      .def(
          "close_batch",
          [](const GraspSimulator& s, const DArray& hand_poses, const py::object& spreads, int threads) {
            const std::vector<Iso3> P = poses(hand_poses, "hand_poses");
            std::vector<double> sp;
            if (py::isinstance<py::float_>(spreads) || py::isinstance<py::int_>(spreads)) {
              sp.push_back(spreads.cast<double>());
            } else {
              const Eigen::VectorXd v = vector(spreads.cast<DArray>(), "spreads");
              sp.assign(v.data(), v.data() + v.size());
            }
            py::gil_scoped_release release;
            return s.close_batch(P, sp, threads);
          },
          py::arg("hand_poses"), py::arg("spreads"), py::arg("threads") = 1,
          R"doc(Auto-grasp of N hand poses (N, 4, 4), spreads a number or (N,), in `threads` C++
threads (0 = all cores), without the GIL. A GraspBatch.)doc")
      .def(
          "top_grasp_batch",
          [](const GraspSimulator& s, const DArray& xyyaw, double spread, double standoff, int threads) {
            const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> rows = matrix(xyyaw, "xyyaw", 3, true);
            py::gil_scoped_release release;
            return s.top_grasp_batch(rows, spread, standoff, threads);
          },
          py::arg("xyyaw"), py::arg("spread"), py::arg("standoff") = 0.0, py::arg("threads") = 1,
          "Top grasps at the rows (x, y, yaw) of an (N, 3) array; a GraspBatch.");
}

}  // namespace

void bind_sim(py::module_& m) {
  bind_contacts(m);
  bind_options(m);
  bind_result(m);
  bind_batch(m);
  py::class_<GraspSimulator> sim(m, "GraspSimulator", R"doc(Auto-grasp of a hand on a static triangle-mesh object.

The object mesh is in the world frame (z up); an infinite table at z = 0 is optional. Fingers
close from the open preshape by conservative advancement with FCL distance queries; each
phalanx stops within contact_tolerance of the object or the table, with breakaway (a stopped
phalanx freezes itself and the earlier ones; the later ones keep closing). Thread-safe.

Args:
    hand: a bayesgrasp._core.hand.Hand.
    vertices: (N, 3) float object vertices (m, world frame).
    faces: (M, 3) int triangles, counter-clockwise seen from outside.
    options: SimOptions (ValueError naming an option out of range).)doc");
  sim.def(py::init([](const HandModel& hand, const DArray& vertices, const IArray& faces, const SimOptions& options) {
             return GraspSimulator(hand, bind::mesh(vertices, faces, "object"), options);
           }),
           py::arg("hand"), py::arg("vertices"), py::arg("faces"), py::arg("options") = SimOptions())
      .def_property_readonly("options", &GraspSimulator::options, "options : SimOptions\n    A copy of the options.")
      .def_property_readonly("num_links", [](const GraspSimulator& s) { return s.hand().num_links(); })
      .def_property_readonly("num_joints", [](const GraspSimulator& s) { return s.hand().num_joints(); })
      .def(
          "close",
          [](const GraspSimulator& s, const DArray& hand_pose, double spread) {
            const Iso3 T = pose(hand_pose, "hand_pose");
            py::gil_scoped_release release;
            return s.close(T, spread);
          },
          py::arg("hand_pose"), py::arg("spread"),
          R"doc(Auto-grasp from a 4x4 world hand pose with the given spread (rad); a GraspResult.)doc")
      .def(
          "close_fixed_step",
          [](const GraspSimulator& s, const DArray& hand_pose, double spread, double step) {
            const Iso3 T = pose(hand_pose, "hand_pose");
            py::gil_scoped_release release;
            return s.close_fixed_step(T, spread, step);
          },
          py::arg("hand_pose"), py::arg("spread"), py::arg("step") = 0.01,
          "The same auto-grasp GraspIt!-style (fixed actuator steps of `step` rad with collision checks, "
          "bisection on a hit); for comparison.")
      .def("top_grasp", &GraspSimulator::top_grasp, py::arg("x"), py::arg("y"), py::arg("yaw"), py::arg("spread"),
           py::arg("standoff") = 0.0, py::call_guard<py::gil_scoped_release>(),
           R"doc(Top grasp: the hand, palm down at (x, y, yaw), moves along -z until any link is within
the contact tolerance of the object or the table, rises by `standoff` (m, >= 0, default 0: the
first touching link stays in contact; and by the table clearance) and closes: the approach along
-z with roll = yaw through (x, y, any z). Its hand_pose is where the hand stopped.)doc")
      .def(
          "link_object_distance",
          [](const GraspSimulator& s, const DArray& hand_pose, const DArray& q, int link) {
            return s.link_object_distance(pose(hand_pose, "hand_pose"), vector(q, "q"), link);
          },
          py::arg("hand_pose"), py::arg("q"), py::arg("link"),
          "Exact distance (m) from one link to the object (not the table); <= 0 when penetrating.");
  def_batches(sim);
  def_approaches(sim);
}

}  // namespace bayesgrasp::bind

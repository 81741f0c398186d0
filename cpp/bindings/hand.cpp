// Bindings for cpp/bayesgrasp/hand: a hand model from a JSON file, its joints, links,
// kinematics and collision shapes (so that Python can draw it).
#include <pybind11/stl.h>

#include "bayesgrasp/hand/hand_model.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace {

Eigen::VectorXd joints_arg(const HandModel& h, const DArray& q) {
  const Eigen::VectorXd v = vector(q, "q");
  h.check_joints(v, 1e-9, "q");
  return v;
}

Iso3 pose_or_identity(const py::object& p, const char* name) {
  if (p.is_none()) return Iso3::Identity();
  return pose(p.cast<DArray>(), name);
}

/// One value per link.
template <class F>
auto per_link(const HandModel& h, F&& value) {
  std::vector<decltype(value(h.links()[0]))> out;
  for (const Link& l : h.links()) out.push_back(value(l));
  return out;
}

const char* type_name(const Shape& s) {
  return s.type == Shape::Type::Box ? "box" : s.type == Shape::Type::Capsule ? "capsule" : "convex";
}

void bind_shape(py::module_& m) {
  py::class_<Shape>(m, "Shape", "A collision primitive of a hand link, in the link frame.")
      .def_property_readonly("type", &type_name, "type : str\n    'box', 'capsule' or 'convex'.")
      .def_property_readonly(
          "vertices",
          [](const Shape& s) {
            Eigen::MatrixX3d V(static_cast<Eigen::Index>(s.vertices.size()), 3);
            for (size_t i = 0; i < s.vertices.size(); ++i) V.row(static_cast<Eigen::Index>(i)) = s.vertices[i].transpose();
            return V;
          },
          "vertices : numpy.ndarray (N, 3)\n    Convex: its vertices, m (empty otherwise).")
      .def_property_readonly(
          "faces",
          [](const Shape& s) {
            Eigen::MatrixX3i F(static_cast<Eigen::Index>(s.faces.size()), 3);
            for (size_t i = 0; i < s.faces.size(); ++i) F.row(static_cast<Eigen::Index>(i)) << s.faces[i][0], s.faces[i][1], s.faces[i][2];
            return F;
          },
          "faces : numpy.ndarray (M, 3) int\n    Convex: its triangles, counter-clockwise seen from outside.")
      .def_property_readonly(
          "center", [](const Shape& s) { return Eigen::Vector3d(s.center); },
          "center : numpy.ndarray (3,)\n    Box centre (box axes = link axes), m.")
      .def_property_readonly(
          "half_extents", [](const Shape& s) { return Eigen::Vector3d(s.half_extents); },
          "half_extents : numpy.ndarray (3,)\n    Box half extents, m.")
      .def_property_readonly(
          "p0", [](const Shape& s) { return Eigen::Vector3d(s.p0); }, "p0 : numpy.ndarray (3,)\n    Capsule axis start, m.")
      .def_property_readonly(
          "p1", [](const Shape& s) { return Eigen::Vector3d(s.p1); }, "p1 : numpy.ndarray (3,)\n    Capsule axis end, m.")
      .def_readonly("radius", &Shape::radius, "radius : float\n    Capsule radius (convex: largest vertex distance from center), m.")
      .def("__repr__", [](const Shape& s) { return std::string("<Shape ") + type_name(s) + ">"; });
}

/// The joint vector, link poses, fingertips and collision shapes.
void def_kinematics(py::class_<HandModel>& hand) {
  hand      .def_property_readonly("spread_default", &HandModel::spread_default, "Default spread (rad).")
      .def_property_readonly(
          "closing",
          [](const HandModel& h) {
            return h.closing() == Closing::Linkage ? "linkage" : h.closing() == Closing::Independent ? "independent" : "breakaway";
          },
          "The closing scheme: 'breakaway' (a stopped phalanx freezes itself and those before it), 'linkage' "
          "(a contact stops the whole finger; couplings of either sign) or 'independent' (one motor per joint).")
      .def_property_readonly(
          "prismatic_joints",
          [](const HandModel& h) {
            std::vector<bool> out(static_cast<size_t>(h.num_joints()), false);
            for (const Finger& f : h.fingers())
              for (size_t p = 0; p < f.phalanges.size(); ++p) out[f.first_joint + p] = f.phalanges[p].prismatic;
            return out;
          },
          "Per entry of q: whether it is a prismatic joint (a jaw's travel, m) rather than an angle (rad).")
      .def_property_readonly("measured_joints", [](const HandModel& h) { return h.measured_joints(); },
                             "Indices into q of the joints the fingers-read measurement uses (the file's measured_joints).")
      .def(
          "coupled_joints",
          [](const HandModel& h, double spread, const py::object& t) {
            h.check_spread(spread);
            if (py::isinstance<py::float_>(t) || py::isinstance<py::int_>(t))
              return Eigen::VectorXd(h.coupled_joints(spread, finite(t.cast<double>(), "t")));
            const Eigen::VectorXd tv = vector(t.cast<DArray>(), "t", static_cast<py::ssize_t>(h.fingers().size()));
            return Eigen::VectorXd(h.coupled_joints(spread, tv));
          },
          py::arg("spread"), py::arg("t") = 0.0,
          R"doc(Joint vector at the given spread with every finger at actuator parameter t
(a number, or one per finger). t = 0 is the open preshape.)doc")
      .def(
          "link_poses",
          [](const HandModel& h, const DArray& q, const py::object& hand_pose) {
            return to_numpy(h.link_poses(pose_or_identity(hand_pose, "hand_pose"), joints_arg(h, q)));
          },
          py::arg("q"), py::arg("hand_pose") = py::none(),
          "(L, 4, 4) poses of every link for joint vector q, in the frame of hand_pose (4x4, default identity).")
      .def(
          "fingertips",
          [](const HandModel& h, const DArray& q, const py::object& hand_pose) {
            const Iso3 T = pose_or_identity(hand_pose, "hand_pose");
            const Eigen::VectorXd v = joints_arg(h, q);
            RowMatrixXd out(static_cast<Eigen::Index>(h.fingers().size()), 3);
            for (int f = 0; f < static_cast<int>(h.fingers().size()); ++f) out.row(f) = h.fingertip(T, f, v).transpose();
            return to_numpy(out);
          },
          py::arg("q"), py::arg("hand_pose") = py::none(), "(F, 3) fingertip positions (end of each last phalanx).")
      .def(
          "link_shapes", [](const HandModel& h) { return per_link(h, [](const Link& l) { return l.shapes; }); },
          "Per link, its collision shapes (Shape) in the link frame.");
}

/// Names and the link layout.
void def_layout(py::class_<HandModel>& hand) {
  hand.def_property_readonly("name", &HandModel::name, "The hand's name.")
      .def_property_readonly("num_joints", &HandModel::num_joints, "Length of the joint vector q.")
      .def_property_readonly("num_links", &HandModel::num_links, "Number of links (0 = palm).")
      .def_property_readonly("num_fingers", [](const HandModel& h) { return static_cast<int>(h.fingers().size()); },
                             "Number of fingers.")
      .def_property_readonly(
          "link_names", [](const HandModel& h) { return per_link(h, [](const Link& l) { return l.name; }); },
          "Link names, e.g. 'palm', 'finger1/proximal'.")
      .def_property_readonly(
          "link_fingers", [](const HandModel& h) { return per_link(h, [](const Link& l) { return l.finger; }); },
          "Finger index of each link (-1 for the palm).")
      .def_property_readonly(
          "link_phalanges", [](const HandModel& h) { return per_link(h, [](const Link& l) { return l.phalanx; }); },
          "Phalanx index of each link within its finger (-1 for palm and knuckles).");
}

/// The joint vector: names, limits, torques, which links each finger drives.
void def_joints(py::class_<HandModel>& hand) {
  hand.def_property_readonly(
          "joint_names",
          [](const HandModel& h) {
            std::vector<std::string> n(h.num_joints());
            n[0] = "spread";
            for (const Finger& f : h.fingers())
              for (size_t p = 0; p < f.phalanges.size(); ++p)
                n[f.first_joint + static_cast<int>(p)] = f.name + "/" + f.phalanges[p].name;
            return n;
          },
          "Names of the joints in q.")
      .def_property_readonly(
          "joint_limits",
          [](const HandModel& h) {
            RowMatrixXd L(h.num_joints(), 2);
            L.row(0) << h.spread_lower(), h.spread_upper();
            for (const Finger& f : h.fingers())
              for (size_t p = 0; p < f.phalanges.size(); ++p)
                L.row(f.first_joint + static_cast<int>(p)) << f.phalanges[p].lower, f.phalanges[p].upper;
            return to_numpy(L);
          },
          "(J, 2) lower and upper limits of q (rad).")
      .def_property_readonly(
          "joint_torques",
          [](const HandModel& h) {
            Eigen::VectorXd t = Eigen::VectorXd::Zero(h.num_joints());
            for (const Finger& f : h.fingers())
              for (size_t p = 0; p < f.phalanges.size(); ++p)
                t[f.first_joint + static_cast<int>(p)] = f.phalanges[p].torque;
            return t;
          },
          "(J,) N m: the finger motor's torque limit at each joint while it drives it (the hand file's "
          "torque_nm; 0 for the spread and where not given).")
      .def_property_readonly(
          "phalanx_links",
          [](const HandModel& h) {
            std::vector<std::vector<int>> out;
            for (const Finger& f : h.fingers()) {
              std::vector<int> l;
              for (const Phalanx& p : f.phalanges) l.push_back(p.link);
              out.push_back(l);
            }
            return out;
          },
          "Per finger, the link indices of its phalanges (base to tip).")
      .def_property_readonly(
          "spread_limits", [](const HandModel& h) { return std::make_pair(h.spread_lower(), h.spread_upper()); },
          "(lower, upper) spread limits (rad).");
}

/// Hand poses from grasp parameters, and repr.
void def_poses(py::class_<HandModel>& hand) {
  hand.def_static(
          "top_grasp_pose",
          [](double x, double y, double yaw, double z) {
            finite(x, "x"), finite(y, "y"), finite(yaw, "yaw"), finite(z, "z");
            return to_numpy(HandModel::top_grasp_pose(x, y, yaw, z));
          },
          py::arg("x"), py::arg("y"), py::arg("yaw"), py::arg("z"),
          "4x4 world pose of a palm-down hand at (x, y, yaw) with its palm face at height z.")
      .def_static(
          "approach_pose",
          [](const DArray& direction, double roll, const DArray& palm) {
            return to_numpy(HandModel::approach_pose(vec3(direction, "direction"), roll, vec3(palm, "palm")));
          },
          py::arg("direction"), py::arg("roll"), py::arg("palm"),
          R"doc(4x4 world pose of a hand approaching along `direction` (its +z, normalised) with
`roll`, palm centre at `palm`. Roll: the palm-down top-grasp hand at yaw = roll tilted by the
smallest rotation taking world -z onto the direction (a right-handed turn about -direction;
for direction -z exactly top_grasp_pose; for +z the tilt is a half turn about world x).
ValueError naming `direction` (zero or not finite), `roll` or `palm`.)doc")
      .def("__repr__", [](const HandModel& h) {
        return "<Hand '" + h.name() + "': " + std::to_string(h.fingers().size()) + " fingers, " +
               std::to_string(h.num_joints()) + " joints>";
      });
}

}  // namespace

void bind_hand(py::module_& m) {
  bind_shape(m);
  py::class_<HandModel> hand(m, "Hand", R"doc(A multi-fingered hand described by a JSON file.

Frames: the hand frame has its origin at the centre of the palm face and +z along the
approach direction. Joint vector q (radians): [spread, finger 0 phalanx 0, finger 0
phalanx 1, ..., finger 1 phalanx 0, ...]; phalanx angles are relative to the previous
phalanx. Each finger closes by one actuator parameter t: phalanx j follows
offset_j + ratio_j * t, clamped to its limits (the coupling), with breakaway.)doc");
  hand.def_static(
          "from_file", [](const std::string& path) { return HandModel::from_file(path); },
          py::arg("path"), "Loads a hand file; ValueError naming the problem if it is missing or invalid.")
      .def_static(
          "from_json", [](const std::string& text) { return HandModel::from_json(text); },
          py::arg("text"), "Parses the JSON text of a hand file; ValueError naming the problem.");
  def_layout(hand);
  def_joints(hand);
  def_poses(hand);
  def_kinematics(hand);
}

}  // namespace bayesgrasp::bind

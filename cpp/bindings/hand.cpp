// Bindings for cpp/bayesgrasp/hand: a hand model from a JSON file, its joints, links,
// kinematics and collision shapes (so that Python can draw it).
#include <pybind11/stl.h>

#include "bayesgrasp/hand/hand_model.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace {

py::array_t<double> poses_array(const std::vector<Iso3>& poses) {
  py::array_t<double> out({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}, py::ssize_t{4}});
  auto o = out.mutable_unchecked<3>();
  for (size_t i = 0; i < poses.size(); ++i)
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) o(static_cast<py::ssize_t>(i), r, c) = poses[i].matrix()(r, c);
  return out;
}

py::array_t<double> matrix4(const Iso3& T) {
  py::array_t<double> out({4, 4});
  auto o = out.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) o(r, c) = T.matrix()(r, c);
  return out;
}

Eigen::VectorXd joints_arg(const HandModel& h, const DArray& q) {
  const Eigen::VectorXd v = vector(q, "q", h.num_joints());
  try {
    h.check_joints(v, 1e-9);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(std::string("q: ") + e.what());
  }
  return v;
}

Iso3 pose_or_identity(const py::object& p, const char* name) {
  if (p.is_none()) return Iso3::Identity();
  return pose(p.cast<DArray>(), name);
}

template <class F>
auto wrap(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

}  // namespace

void bind_hand(py::module_& m) {
  py::class_<HandModel>(m, "Hand", R"doc(A multi-fingered hand described by a JSON file.

Frames: the hand frame has its origin at the centre of the palm face and +z along the
approach direction. Joint vector q (radians): [spread, finger 0 phalanx 0, finger 0
phalanx 1, ..., finger 1 phalanx 0, ...]; phalanx angles are relative to the previous
phalanx. Each finger closes by one actuator parameter t: phalanx j follows
offset_j + ratio_j * t, clamped to its limits (the coupling), with breakaway.)doc")
      .def_static(
          "from_file", [](const std::string& path) { return wrap([&] { return HandModel::from_file(path); }); },
          py::arg("path"), "Loads a hand file; ValueError naming the problem if it is missing or invalid.")
      .def_static(
          "from_json", [](const std::string& text) { return wrap([&] { return HandModel::from_json(text); }); },
          py::arg("text"), "Parses the JSON text of a hand file; ValueError naming the problem.")
      .def_property_readonly("name", &HandModel::name, "The hand's name.")
      .def_property_readonly("num_joints", &HandModel::num_joints, "Length of the joint vector q.")
      .def_property_readonly("num_links", &HandModel::num_links, "Number of links (0 = palm).")
      .def_property_readonly("num_fingers", [](const HandModel& h) { return static_cast<int>(h.fingers().size()); },
                             "Number of fingers.")
      .def_property_readonly(
          "link_names",
          [](const HandModel& h) {
            std::vector<std::string> n;
            for (const Link& l : h.links()) n.push_back(l.name);
            return n;
          },
          "Link names, e.g. 'palm', 'finger1/proximal'.")
      .def_property_readonly(
          "link_fingers",
          [](const HandModel& h) {
            std::vector<int> n;
            for (const Link& l : h.links()) n.push_back(l.finger);
            return n;
          },
          "Finger index of each link (-1 for the palm).")
      .def_property_readonly(
          "link_phalanges",
          [](const HandModel& h) {
            std::vector<int> n;
            for (const Link& l : h.links()) n.push_back(l.phalanx);
            return n;
          },
          "Phalanx index of each link within its finger (-1 for palm and knuckles).")
      .def_property_readonly(
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
      .def_property_readonly("spread_default", &HandModel::spread_default, "Default spread (rad).")
      .def(
          "coupled_joints",
          [](const HandModel& h, double spread, const py::object& t) {
            finite(spread, "spread");
            if (spread < h.spread_lower() - 1e-12 || spread > h.spread_upper() + 1e-12)
              throw py::value_error("spread: outside the hand's limits");
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
            return poses_array(h.link_poses(pose_or_identity(hand_pose, "hand_pose"), joints_arg(h, q)));
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
          "link_shapes",
          [](const HandModel& h) {
            py::list out;
            for (const Link& l : h.links()) {
              py::list shapes;
              for (const Shape& s : l.shapes) {
                py::dict d;
                if (s.type == Shape::Type::Box) {
                  d["type"] = "box";
                  d["center"] = Eigen::Vector3d(s.center);
                  d["half_extents"] = Eigen::Vector3d(s.half_extents);
                } else {
                  d["type"] = "capsule";
                  d["p0"] = Eigen::Vector3d(s.p0);
                  d["p1"] = Eigen::Vector3d(s.p1);
                  d["radius"] = s.radius;
                }
                shapes.append(d);
              }
              out.append(shapes);
            }
            return out;
          },
          R"doc(Per link, its collision shapes in the link frame: dicts with type 'box'
(center, half_extents; box axes = link axes) or 'capsule' (p0, p1, radius).)doc")
      .def_property_readonly(
          "spread_limits", [](const HandModel& h) { return std::make_pair(h.spread_lower(), h.spread_upper()); },
          "(lower, upper) spread limits (rad).")
      .def_static(
          "top_grasp_pose",
          [](double x, double y, double yaw, double z) {
            finite(x, "x"), finite(y, "y"), finite(yaw, "yaw"), finite(z, "z");
            return matrix4(HandModel::top_grasp_pose(x, y, yaw, z));
          },
          py::arg("x"), py::arg("y"), py::arg("yaw"), py::arg("z"),
          "4x4 world pose of a palm-down hand at (x, y, yaw) with its palm face at height z.")
      .def("__repr__", [](const HandModel& h) {
        return "<Hand '" + h.name() + "': " + std::to_string(h.fingers().size()) + " fingers, " +
               std::to_string(h.num_joints()) + " joints>";
      });
}

}  // namespace bayesgrasp::bind

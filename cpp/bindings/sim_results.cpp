// Bindings of the grasp simulator's results: contacts, one grasp (GraspResult) and a batch
// (GraspBatch). The array fields are read-only numpy views of the C++ results (no copies).
#include <pybind11/stl.h>

#include <type_traits>

#include "bayesgrasp/sim/grasp_simulator.hpp"
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

}  // namespace

void bind_sim_results(py::module_& m) {
  bind_contacts(m);
  bind_result(m);
  bind_batch(m);
}

}  // namespace bayesgrasp::bind

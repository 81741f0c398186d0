// Bindings for cpp/bayesgrasp/sim: the grasp simulator (auto-grasp with breakaway, top grasps,
// batches with the GIL released). Results are dicts of numpy arrays.
#include <pybind11/stl.h>

#include "bayesgrasp/sim/grasp_simulator.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace {

py::array_t<double> matrix4(const Iso3& T) {
  py::array_t<double> out({4, 4});
  auto o = out.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) o(r, c) = T.matrix()(r, c);
  return out;
}

py::dict contacts_dict(const Contacts& cs, const std::vector<int64_t>* offsets) {
  const py::ssize_t K = static_cast<py::ssize_t>(cs.size());
  py::array_t<double> point({K, py::ssize_t{3}}), normal({K, py::ssize_t{3}});
  py::array_t<int> link(K);
  py::array_t<double> pen(K);
  py::array_t<bool> table(K);
  auto p = point.mutable_unchecked<2>();
  auto n = normal.mutable_unchecked<2>();
  auto l = link.mutable_unchecked<1>();
  auto d = pen.mutable_unchecked<1>();
  auto t = table.mutable_unchecked<1>();
  for (py::ssize_t k = 0; k < K; ++k) {
    const Contact& c = cs[k];
    for (int i = 0; i < 3; ++i) p(k, i) = c.point[i], n(k, i) = c.normal[i];
    l(k) = c.link;
    d(k) = c.penetration;
    t(k) = c.on_table;
  }
  py::dict out;
  out["point"] = point;
  out["normal"] = normal;
  out["link"] = link;
  out["penetration"] = pen;
  out["on_table"] = table;
  if (offsets) {
    py::array_t<int64_t> grasp(K);
    auto g = grasp.mutable_unchecked<1>();
    for (size_t i = 0; i + 1 < offsets->size(); ++i)
      for (int64_t k = (*offsets)[i]; k < (*offsets)[i + 1]; ++k) g(k) = static_cast<int64_t>(i);
    out["grasp"] = grasp;
    out["offsets"] = py::array_t<int64_t>(static_cast<py::ssize_t>(offsets->size()), offsets->data());
  }
  return out;
}

template <class V>
py::array_t<bool> bools(const V& v) {
  py::array_t<bool> out(static_cast<py::ssize_t>(v.size()));
  auto o = out.mutable_unchecked<1>();
  for (size_t i = 0; i < v.size(); ++i) o(static_cast<py::ssize_t>(i)) = v[i] != 0;
  return out;
}

py::dict result_dict(const GraspResult& r) {
  py::dict d;
  d["joint_angles"] = Eigen::VectorXd(r.joints);
  d["contacts"] = contacts_dict(r.contacts, nullptr);
  d["link_contact"] = bools(r.link_contact);
  d["table_contact"] = bools(r.table_contact);
  d["collision_at_start"] = r.collision_at_start;
  d["hand_pose"] = matrix4(r.hand_pose);
  d["distance_queries"] = r.distance_queries;
  return d;
}

py::array_t<bool> bool_matrix(const Eigen::Matrix<uint8_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& m) {
  py::array_t<bool> out({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  auto o = out.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) o(i, j) = m(i, j) != 0;
  return out;
}

py::dict batch_dict(const GraspBatch& b) {
  py::dict d;
  d["joint_angles"] = to_numpy(b.joints);
  d["contacts"] = contacts_dict(b.contacts, &b.offsets);
  d["link_contact"] = bool_matrix(b.link_contact);
  d["table_contact"] = bool_matrix(b.table_contact);
  d["collision_at_start"] = bools(b.collision_at_start);
  py::array_t<double> poses({static_cast<py::ssize_t>(b.num_grasps), py::ssize_t{4}, py::ssize_t{4}});
  auto o = poses.mutable_unchecked<3>();
  for (int i = 0; i < b.num_grasps; ++i)
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) o(i, r, c) = b.hand_poses[i].matrix()(r, c);
  d["hand_pose"] = poses;
  d["distance_queries"] = py::array_t<int>(static_cast<py::ssize_t>(b.distance_queries.size()), b.distance_queries.data());
  return d;
}

double spread_arg(const GraspSimulator& s, double spread) {
  finite(spread, "spread");
  const HandModel& h = s.hand();
  if (spread < h.spread_lower() - 1e-12 || spread > h.spread_upper() + 1e-12)
    throw py::value_error("spread: must lie in [" + std::to_string(h.spread_lower()) + ", " +
                          std::to_string(h.spread_upper()) + "] rad, got " + std::to_string(spread));
  return spread;
}

double standoff_arg(double standoff) {
  if (!std::isfinite(standoff) || standoff < 0)
    throw py::value_error("standoff: must be >= 0 and finite, got " + std::to_string(standoff));
  return standoff;
}

int threads_arg(int threads) {
  if (threads < 0) throw py::value_error("threads: must be >= 0 (0 = all cores)");
  return threads;
}

std::vector<Iso3> poses_arg(const DArray& a, const char* name) {
  if (a.ndim() != 3 || a.shape(1) != 4 || a.shape(2) != 4)
    throw py::value_error(std::string(name) + ": expected shape (N, 4, 4), got " + shape_str(a));
  std::vector<Iso3> out(a.shape(0));
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> m(a.data() + 16 * i);
    try {
      out[i] = pose_from_matrix(m);
    } catch (const std::invalid_argument& e) {
      throw py::value_error(std::string(name) + "[" + std::to_string(i) + "]: " + e.what());
    }
  }
  return out;
}

}  // namespace

void bind_sim(py::module_& m) {
  py::class_<GraspSimulator>(m, "GraspSimulator", R"doc(Auto-grasp of a hand on a static triangle-mesh object.

The object mesh is in the world frame (z up); an infinite table at z = 0 is optional. Fingers
close from the open preshape by conservative advancement with FCL distance queries; each
phalanx stops within contact_tolerance of the object or the table, with breakaway (a stopped
phalanx freezes itself and the earlier ones; the later ones keep closing). Thread-safe.)doc")
      .def(py::init([](const HandModel& hand, const DArray& vertices, const IArray& faces, bool table,
                       double contact_tolerance, double table_clearance) {
             const TriMesh mesh = bind::mesh(vertices, faces, "object");
             SimOptions o;
             o.table = table;
             o.table_clearance = finite(table_clearance, "table_clearance");
             o.contact_tolerance = positive(contact_tolerance, "contact_tolerance");
             o.box_skip = std::max(o.box_skip, 2.5 * o.contact_tolerance);
             return GraspSimulator(hand, mesh, o);
           }),
           py::arg("hand"), py::arg("vertices"), py::arg("faces"), py::arg("table") = true,
           py::arg("contact_tolerance") = 2e-4, py::arg("table_clearance") = SimOptions{}.table_clearance,
           R"doc(Args:
    hand: a bayesgrasp._core.hand.Hand.
    vertices: (N, 3) float object vertices (m, world frame).
    faces: (M, 3) int triangles, counter-clockwise seen from outside.
    table: add the table plane z = 0.
    contact_tolerance: a link touches when closer than this (m, default 0.2 mm).
    table_clearance: top grasps keep the fingers' closing sweep at least this far above the
        table (m, default 5 mm); negative: stop at the first contact instead.)doc")
      .def_property_readonly("num_links", [](const GraspSimulator& s) { return s.hand().num_links(); })
      .def_property_readonly("num_joints", [](const GraspSimulator& s) { return s.hand().num_joints(); })
      .def(
          "close",
          [](const GraspSimulator& s, const DArray& hand_pose, double spread) {
            const Iso3 T = pose(hand_pose, "hand_pose");
            spread_arg(s, spread);
            GraspResult r;
            {
              py::gil_scoped_release release;
              r = s.close(T, spread);
            }
            return result_dict(r);
          },
          py::arg("hand_pose"), py::arg("spread"),
          R"doc(Auto-grasp from a 4x4 world hand pose with the given spread (rad).

Returns a dict: joint_angles (J,), contacts {point (K,3), normal (K,3) (the object's outward
normal, +z for the table), link (K,), penetration (K,), on_table (K,)}, link_contact (L,)
and table_contact (L,) booleans, collision_at_start (bool: the open hand penetrated the
object or table; fingers then stay open and there are no contacts), hand_pose (4,4),
distance_queries (int).)doc")
      .def(
          "close_fixed_step",
          [](const GraspSimulator& s, const DArray& hand_pose, double spread, double step) {
            const Iso3 T = pose(hand_pose, "hand_pose");
            spread_arg(s, spread);
            positive(step, "step");
            GraspResult r;
            {
              py::gil_scoped_release release;
              r = s.close_fixed_step(T, spread, step);
            }
            return result_dict(r);
          },
          py::arg("hand_pose"), py::arg("spread"), py::arg("step") = 0.01,
          "The same auto-grasp GraspIt!-style (fixed actuator steps + collision checks, bisection on a hit); for comparison.")
      .def(
          "top_grasp",
          [](const GraspSimulator& s, double x, double y, double yaw, double spread, double standoff) {
            finite(x, "x"), finite(y, "y"), finite(yaw, "yaw");
            spread_arg(s, spread);
            standoff_arg(standoff);
            GraspResult r;
            {
              py::gil_scoped_release release;
              r = s.top_grasp(x, y, yaw, spread, standoff);
            }
            return result_dict(r);
          },
          py::arg("x"), py::arg("y"), py::arg("yaw"), py::arg("spread"), py::arg("standoff") = 0.0,
          R"doc(Top grasp: the hand, palm down at (x, y, yaw), descends along -z until any link is
within the contact tolerance of the object or the table, rises by `standoff` (m, >= 0,
default 0: the first touching link stays in contact) and closes. Same dict as close(); its
hand_pose is where the hand stopped.)doc")
      .def(
          "close_batch",
          [](const GraspSimulator& s, const DArray& hand_poses, const py::object& spreads, int threads) {
            const std::vector<Iso3> poses = poses_arg(hand_poses, "hand_poses");
            std::vector<double> sp;
            if (py::isinstance<py::float_>(spreads) || py::isinstance<py::int_>(spreads)) {
              sp.push_back(spread_arg(s, spreads.cast<double>()));
            } else {
              const Eigen::VectorXd v = vector(spreads.cast<DArray>(), "spreads", static_cast<py::ssize_t>(poses.size()));
              for (Eigen::Index i = 0; i < v.size(); ++i) sp.push_back(spread_arg(s, v[i]));
            }
            threads_arg(threads);
            GraspBatch b;
            {
              py::gil_scoped_release release;
              b = s.close_batch(poses, sp, threads);
            }
            return batch_dict(b);
          },
          py::arg("hand_poses"), py::arg("spreads"), py::arg("threads") = 1,
          R"doc(Auto-grasp of N hand poses (N, 4, 4), spreads a number or (N,), in `threads` C++
threads (0 = all cores), without the GIL. Returns a dict of arrays: joint_angles (N, J),
link_contact and table_contact (N, L), collision_at_start (N,), hand_pose (N, 4, 4),
distance_queries (N,), contacts {point (K,3), normal (K,3), link, penetration, on_table,
grasp (K,) (the grasp index of each contact), offsets (N+1,) (grasp i's contacts are rows
offsets[i]:offsets[i+1])}.)doc")
      .def(
          "top_grasp_batch",
          [](const GraspSimulator& s, const DArray& xyyaw, double spread, double standoff, int threads) {
            const RowMatrixXd a = matrix(xyyaw, "xyyaw", 3, true);
            spread_arg(s, spread);
            standoff_arg(standoff);
            threads_arg(threads);
            const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> rows = a;
            GraspBatch b;
            {
              py::gil_scoped_release release;
              b = s.top_grasp_batch(rows, spread, standoff, threads);
            }
            return batch_dict(b);
          },
          py::arg("xyyaw"), py::arg("spread"), py::arg("standoff") = 0.0, py::arg("threads") = 1,
          "Top grasps at the rows (x, y, yaw) of an (N, 3) array; same dict as close_batch().")
      .def(
          "link_object_distance",
          [](const GraspSimulator& s, const DArray& hand_pose, const DArray& q, int link) {
            const Iso3 T = pose(hand_pose, "hand_pose");
            const Eigen::VectorXd v = vector(q, "q", s.hand().num_joints());
            if (link < 0 || link >= s.hand().num_links()) throw py::value_error("link: out of range");
            try {
              return s.link_object_distance(T, v, link);
            } catch (const std::invalid_argument& e) {
              throw py::value_error(std::string("q: ") + e.what());
            }
          },
          py::arg("hand_pose"), py::arg("q"), py::arg("link"),
          "Exact distance (m) from one link to the object (not the table); <= 0 when penetrating.");
}

}  // namespace bayesgrasp::bind

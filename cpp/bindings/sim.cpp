// Bindings for cpp/bayesgrasp/sim: the grasp simulator (auto-grasp with breakaway, approaches
// and top grasps, batches with the GIL released) and its options; its results are bound in
// sim_results.cpp. Arguments are validated by the core (std::invalid_argument becomes ValueError).
#include <pybind11/stl.h>

#include <type_traits>

#include "bayesgrasp/sim/grasp_simulator.hpp"
#include "options.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

void bind_sim_results(py::module_& m);

namespace {

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
  bind_options(m);
  bind_sim_results(m);
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

// Bindings for cpp/bayesgrasp/touch (Pub. I): the executed grasp and its readings, the touch
// model (the grasp re-simulated against N candidate object states), the fitness and the
// estimate. Options and results are bound classes; validation is the core's (its
// std::invalid_argument becomes ValueError); long calls release the GIL.
#include <pybind11/stl.h>

#include "bayesgrasp/touch/estimate.hpp"
#include "options.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace {

using namespace bayesgrasp::touch;
using FlagMatrix = Eigen::Matrix<uint8_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

py::array_t<bool> bools(const std::vector<uint8_t>& v) {
  py::array_t<bool> out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

py::array_t<bool> bools(const FlagMatrix& m) {
  py::array_t<bool> out({m.rows(), m.cols()});
  std::copy(m.data(), m.data() + m.size(), out.mutable_data());
  return out;
}

std::vector<uint8_t> flags(const py::array_t<bool, py::array::c_style | py::array::forcecast>& a,
                           const char* name) {
  if (a.ndim() != 1) throw py::value_error(std::string(name) + ": expected a 1-D array of flags, got " + shape_str(a));
  return std::vector<uint8_t>(a.data(), a.data() + a.shape(0));
}

using BoolArray = py::array_t<bool, py::array::c_style | py::array::forcecast>;

/// Readings from arrays: shapes are checked here, values (finiteness, sizes) by the core when used.
TouchReadings readings_from(const DArray& joints, const BoolArray& contact, const DArray& hand_pose) {
  if (joints.ndim() != 1) throw py::value_error("joints: expected a 1-D array, got " + shape_str(joints));
  if (hand_pose.ndim() != 2 || hand_pose.shape(0) != 4 || hand_pose.shape(1) != 4)
    throw py::value_error("hand_pose: expected shape (4, 4), got " + shape_str(hand_pose));
  TouchReadings r;
  r.joints = Eigen::Map<const Eigen::VectorXd>(joints.data(), joints.shape(0));
  r.contact = flags(contact, "contact");
  r.hand_pose.matrix() = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(hand_pose.data());
  return r;
}

void bind_enums(py::module_& m) {
  py::enum_<Optimizer>(m, "Optimizer", "The optimisers Pub. I compares (and a trust region).")
      .value("descent", Optimizer::Descent)
      .value("annealing", Optimizer::Annealing)
      .value("pso", Optimizer::PSO)
      .value("firefly", Optimizer::Firefly)
      .value("trust_region", Optimizer::TrustRegion);
  py::enum_<Unknowns>(m, "Unknowns", "What the touch estimates: pose (x, y, yaw), pose_and_scale, orientation (yaw).")
      .value("pose", Unknowns::Pose)
      .value("pose_and_scale", Unknowns::PoseAndScale)
      .value("orientation", Unknowns::Orientation);
  py::enum_<ContactTerm>(m, "ContactTerm", "The fitness's contact term: 0/1 flags, or the continuous surface term.")
      .value("flags", ContactTerm::Flags)
      .value("surface", ContactTerm::Surface);
  py::enum_<EstimateStatus>(m, "EstimateStatus", "estimated, or no_contact (nothing learnt).")
      .value("estimated", EstimateStatus::Estimated)
      .value("no_contact", EstimateStatus::NoContact);
}

void bind_grasp_and_readings(py::module_& m) {
  py::class_<TouchGrasp> g(m, "TouchGrasp",
                           "The executed grasp (world frame): a top grasp or a closing at a hand pose.");
  py::enum_<TouchGrasp::Kind>(g, "Kind").value("top_grasp", TouchGrasp::Kind::TopGrasp)
      .value("closing", TouchGrasp::Kind::Closing);
  g.def_static("top", &TouchGrasp::top, py::arg("x"), py::arg("y"), py::arg("yaw"), py::arg("spread"),
               py::arg("standoff") = 0.0, "Palm-down descent at (x, y, yaw) to the first contact, then closing.")
      .def_static(
          "closing", [](const DArray& H, double spread) { return TouchGrasp::closing(pose(H, "hand_pose"), spread); },
                  py::arg("hand_pose"), py::arg("spread"), "Closing at a known 4x4 world hand pose.")
      .def_readonly("kind", &TouchGrasp::kind, "kind : TouchGrasp.Kind\n    top_grasp or closing")
      .def_readonly("x", &TouchGrasp::x, "x : float\n    top grasp x (m)")
      .def_readonly("y", &TouchGrasp::y, "y : float\n    top grasp y (m)")
      .def_readonly("yaw", &TouchGrasp::yaw, "yaw : float\n    top grasp yaw (rad)")
      .def_readonly("standoff", &TouchGrasp::standoff, "standoff : float\n    back-off after the first contact (m)")
      .def_readonly("spread", &TouchGrasp::spread, "spread : float\n    finger spread (rad)")
      .def_property_readonly("hand_pose", [](const TouchGrasp& t) { return to_numpy(t.hand_pose); },
                             "hand_pose : numpy.ndarray (4, 4)\n    closing: the hand pose");

  py::class_<TouchReadings>(m, "TouchReadings", "What the hand read after closing.")
      .def(py::init(&readings_from),
           py::arg("joints"), py::arg("contact"), py::arg("hand_pose"),
           "joints (J,) rad; contact (L,) bool per link; hand_pose (4, 4). Checked when used (ValueError).")
      .def_static("from_grasp", &readings_of, py::arg("result"), "The readings of a simulated GraspResult.")
      .def_readonly("joints", &TouchReadings::joints,
                    "joints : numpy.ndarray (J,)\n    joint angles (rad), hand layout")
      .def_property_readonly("contact", [](const TouchReadings& r) { return bools(r.contact); },
                             "contact : numpy.ndarray (L,) bool\n    per link: it touches the object")
      .def_property_readonly("hand_pose", [](const TouchReadings& r) { return to_numpy(r.hand_pose); },
                             "hand_pose : numpy.ndarray (4, 4)\n    world pose at which the hand closed")
      .def_property_readonly("contact_count", &TouchReadings::contact_count,
                             "contact_count : int\n    links touching the object");
  m.def("execute", &execute, py::arg("world"), py::arg("grasp"), py::call_guard<py::gil_scoped_release>(),
        "The grasp executed on a GraspSimulator whose object is in the world frame: a GraspResult.");
}

void bind_options(py::module_& m) {
  OptionClass<TouchModelOptions>(m, "TouchModelOptions", "Options of the touch model.")
      .field("sim", &TouchModelOptions::sim, "SimOptions", "the simulator's options (as the world's)")
      .field("scale_step", &TouchModelOptions::scale_step, "float",
             "candidate scales are rounded to multiples of this (> 0)")
      .field("scale_min", &TouchModelOptions::scale_min, "float", "smallest candidate scale")
      .field("scale_max", &TouchModelOptions::scale_max, "float", "largest candidate scale")
      .validator([](const TouchModelOptions& o) { validate(o); })
      .finish();
  OptionClass<FitnessOptions>(m, "FitnessOptions", "Weights of Pub. I's fitness (see touch/fitness.hpp).")
      .field("joint_sigma", &FitnessOptions::joint_sigma, "float", "sigma_q (rad)")
      .field("joint_weights", &FitnessOptions::joint_weights, "numpy.ndarray (J,)",
             "w_j; empty = 0 for the spread, 1 for each phalanx")
      .field("contact_term", &FitnessOptions::contact_term, "ContactTerm", "flags or surface")
      .field("contact_weight", &FitnessOptions::contact_weight, "float", "lambda_c")
      .field("surface_scale", &FitnessOptions::surface_scale, "float", "d_s (m)")
      .field("height_sigma", &FitnessOptions::height_sigma, "float", "sigma_z (m)")
      .field("collision_penalty", &FitnessOptions::collision_penalty, "float",
             "added when the open hand starts inside the candidate")
      .validator([](const FitnessOptions& o) { validate(o); })
      .finish();
  OptionClass<SearchBox>(m, "SearchBox", "The search box around the initial guess.")
      .field("xy", &SearchBox::xy, "float", "+- x and y (m)")
      .field("yaw", &SearchBox::yaw, "float", "+- yaw (rad)")
      .field("scale_low", &SearchBox::scale_low, "float", "smallest scale")
      .field("scale_high", &SearchBox::scale_high, "float", "largest scale")
      .validator([](const SearchBox& o) { validate(o); })
      .finish();
  OptionClass<EstimateOptions>(m, "EstimateOptions", "How one touch is turned into an estimate.")
      .field("optimizer", &EstimateOptions::optimizer, "Optimizer", "the search (PSO by default)")
      .field("unknowns", &EstimateOptions::unknowns, "Unknowns", "pose (x, y, yaw) or pose and scale")
      .field("box", &EstimateOptions::box, "SearchBox", "the search box around the initial guess")
      .field("fitness", &EstimateOptions::fitness, "FitnessOptions", "the fitness' weights")
      .field("budget", &EstimateOptions::budget, "int", "fitness evaluations")
      .field("population", &EstimateOptions::population, "int",
             "particles / fireflies / chains; 0 = the default (20, 20, 10)")
      .field("seed", &EstimateOptions::seed, "int", "seed of the search")
      .field("threads", &EstimateOptions::threads, "int", "0 = all cores")
      .field("stop_fitness", &EstimateOptions::stop_fitness, "float",
             "end the search once the best fitness is below this (the readings reproduced to that level); 0 = "
             "spend the whole budget")
      .validator([](const EstimateOptions& o) { validate(o); })
      .finish();
  m.def("minimum_budget", &minimum_budget, py::arg("optimizer"), py::arg("dim"), py::arg("population") = 0,
        "The smallest budget the optimiser runs with in `dim` unknowns.");
}

/// EstimateResult as plain Python values (the status by name, arrays as lists): one key set.
py::dict estimate_dict(const EstimateResult& r) {
  py::dict d;
  d["status"] = r.status == EstimateStatus::Estimated ? "estimated" : "no_contact";
  d["message"] = r.message;
  d["initial"] = std::vector<double>(r.initial.data(), r.initial.data() + r.initial.size());
  d["state"] = std::vector<double>(r.state.data(), r.state.data() + r.state.size());
  d["initial_fitness"] = r.initial_fitness;
  d["fitness"] = r.fitness;
  d["fitness_terms"] = py::dict(py::arg("joint") = r.joint_term, py::arg("contact") = r.contact_term,
                                py::arg("height") = r.height_term);
  d["evaluations"] = r.evaluations;
  d["stopped"] = r.stopped;
  d["restarts"] = r.restarts;
  d["trace"] = py::dict(py::arg("evaluations") = r.trace_evaluations, py::arg("best_fitness") = r.trace_fitness);
  d["seconds"] = r.seconds;
  d["cpu_seconds"] = r.cpu_seconds;
  return d;
}

void bind_results(py::module_& m) {
  py::class_<TouchPredictions>(m, "TouchPredictions", "Predicted readings of N candidates (row i = candidate i).")
      .def_readonly("num_candidates", &TouchPredictions::num_candidates, "num_candidates : int")
      .def_readonly("joints", &TouchPredictions::joints, "joints : numpy.ndarray (N, J)\n    joint angles (rad)")
      .def_property_readonly("contact", [](const TouchPredictions& p) { return bools(p.contact); },
                             "contact : numpy.ndarray (N, L) bool\n    per link: touches the candidate")
      .def_readonly("hand_height", &TouchPredictions::hand_height,
                    "hand_height : numpy.ndarray (N,)\n    z of the hand (m)")
      .def_property_readonly("collision_at_start",
                             [](const TouchPredictions& p) { return bools(p.collision_at_start); },
                             "collision_at_start : numpy.ndarray (N,) bool")
      .def_readonly("surface_distance", &TouchPredictions::surface_distance,
                    "surface_distance : numpy.ndarray (N, L)\n    links of the measured hand that touched: distance to "
                    "the candidate's surface (m); NaN for the others")
      .def_property_readonly("penetrating", [](const TouchPredictions& p) { return bools(p.penetrating); },
                             "penetrating : numpy.ndarray (N, L) bool\n    links of the measured hand that did not touch: "
                             "inside the candidate")
      .def_readonly("scales", &TouchPredictions::scales, "scales : numpy.ndarray (N,)\n    quantised scales simulated");
  py::class_<FitnessTerms>(m, "FitnessTerms", "Pub. I's fitness per candidate and its terms.")
      .def_readonly("joint", &FitnessTerms::joint, "joint : numpy.ndarray (N,)")
      .def_readonly("contact", &FitnessTerms::contact, "contact : numpy.ndarray (N,)")
      .def_readonly("height", &FitnessTerms::height, "height : numpy.ndarray (N,)")
      .def_readonly("total", &FitnessTerms::total, "total : numpy.ndarray (N,)\n    f");
  py::class_<EstimateResult>(m, "EstimateResult", "One touch's estimate.")
      .def_readonly("status", &EstimateResult::status, "status : EstimateStatus")
      .def_readonly("message", &EstimateResult::message, "message : str")
      .def_readonly("initial", &EstimateResult::initial, "initial : numpy.ndarray (4,)\n    x, y, yaw, scale")
      .def_readonly("state", &EstimateResult::state, "state : numpy.ndarray (4,)\n    the estimate")
      .def_readonly("initial_fitness", &EstimateResult::initial_fitness, "initial_fitness : float")
      .def_readonly("fitness", &EstimateResult::fitness, "fitness : float\n    f at the estimate")
      .def_readonly("joint_term", &EstimateResult::joint_term, "joint_term : float")
      .def_readonly("contact_term", &EstimateResult::contact_term, "contact_term : float")
      .def_readonly("height_term", &EstimateResult::height_term, "height_term : float")
      .def_readonly("evaluations", &EstimateResult::evaluations, "evaluations : int")
      .def_readonly("stopped", &EstimateResult::stopped,
                    "stopped : bool\n    the search ended below stop_fitness, before its budget")
      .def_readonly("restarts", &EstimateResult::restarts, "restarts : int\n    local optimisers: runs after the first")
      .def_readonly("trace_evaluations", &EstimateResult::trace_evaluations,
                    "trace_evaluations : list of int\n    evaluations after each batch")
      .def_readonly("trace_fitness", &EstimateResult::trace_fitness, "trace_fitness : list of float\n    best f so far")
      .def_readonly("seconds", &EstimateResult::seconds, "seconds : float\n    wall time of the search")
      .def_readonly("cpu_seconds", &EstimateResult::cpu_seconds,
                    "cpu_seconds : float\n    processor time of the search (all threads)")
      .def("to_dict", &estimate_dict,
           "{'status', 'message', 'initial', 'state', 'initial_fitness', 'fitness', 'fitness_terms': {'joint', "
           "'contact', 'height'}, 'evaluations', 'stopped', 'restarts', 'trace': {'evaluations', 'best_fitness'}, "
           "'seconds', 'cpu_seconds'} as plain Python values.");
}

/// States as the core takes them (an array that is not 2-D becomes 0 x 0: the core names the problem).
RowMatrixXd states_from(const DArray& a) {
  if (a.ndim() != 2) return RowMatrixXd(0, 0);
  return Eigen::Map<const RowMatrixXd>(a.data(), a.shape(0), a.shape(1));
}

void bind_model(py::module_& m) {
  py::class_<TouchModel>(m, "TouchModel", R"doc(The executed grasp re-simulated against candidate object states.

Args:
    hand: a bayesgrasp._core.hand.Hand.
    vertices, faces: the object in its own frame (xy-box centre on the z axis, lowest point z = 0).
    options: TouchModelOptions.)doc")
      .def(py::init([](const HandModel& hand, const DArray& V, const IArray& F, const TouchModelOptions& o) {
             return std::make_unique<TouchModel>(hand, bind::mesh(V, F, "object"), o);
           }),
           py::arg("hand"), py::arg("vertices"), py::arg("faces"), py::arg("options") = TouchModelOptions())
      .def_property_readonly("options", &TouchModel::options, "options : TouchModelOptions")
      .def("quantised_scale", &TouchModel::quantised_scale, py::arg("scale"))
      .def_property_readonly("cached_scales", &TouchModel::cached_scales, "cached_scales : int\n    simulators built")
      .def(
          "predict",
          [](const TouchModel& t, const TouchGrasp& g, const DArray& states, const TouchReadings* measured,
             int threads) {
            const RowMatrixXd S = states_from(states);
            py::gil_scoped_release release;
            return measured ? t.predict(g, S, *measured, threads) : t.predict(g, S, threads);
          },
          py::arg("grasp"), py::arg("states"), py::arg("measured") = nullptr, py::arg("threads") = 1,
          "Predicted readings at states (N, 3) x, y, yaw or (N, 4) with scale; with `measured`, also the surface "
          "distances of the measured hand.")
      .def(
          "fitness",
          [](const TouchModel& t, const TouchGrasp& g, const TouchReadings& measured, const DArray& states,
             const FitnessOptions& o, int threads) {
            const RowMatrixXd S = states_from(states);
            py::gil_scoped_release release;
            return evaluate_fitness(t, g, measured, S, o, threads);
          },
          py::arg("grasp"), py::arg("measured"), py::arg("states"), py::arg("options") = FitnessOptions(),
          py::arg("threads") = 1, "Pub. I's fitness at states (N, 3) or (N, 4): FitnessTerms.")
      .def(
          "estimate",
          [](const TouchModel& t, const TouchGrasp& g, const TouchReadings& measured, const DArray& initial,
             const EstimateOptions& o) {
            const State s0 = vector(initial, "initial", 4);
            py::gil_scoped_release release;
            return estimate(t, g, measured, s0, o);
          },
          py::arg("grasp"), py::arg("measured"), py::arg("initial"), py::arg("options") = EstimateOptions(),
          "The object state (x, y, yaw, scale) minimising the fitness, from `initial` (4,): EstimateResult.");
}

}  // namespace

void bind_touch(py::module_& m) {
  bind_enums(m);
  bind_grasp_and_readings(m);
  bind_options(m);
  bind_results(m);
  bind_model(m);
}

}  // namespace bayesgrasp::bind

// bayesgrasp._core: one binding file per concept, each registering into its own submodule.
#include <pybind11/pybind11.h>

namespace py = pybind11;

namespace bayesgrasp::bind {
void bind_geometry(py::module_& m);
void bind_hand(py::module_& m);
void bind_sim(py::module_& m);
void bind_quality(py::module_& m);
void bind_physics(py::module_& m);
void bind_gp(py::module_& m);
void bind_belief(py::module_& m);
void bind_optim(py::module_& m);
void bind_vision(py::module_& m);
void bind_task(py::module_& m);
}  // namespace bayesgrasp::bind

PYBIND11_MODULE(_core, m) {
  m.doc() = "bayesgrasp C++ core: contact simulation, grasp quality, GPs, beliefs, optimisers.";
  using namespace bayesgrasp::bind;
  auto geometry = m.def_submodule("geometry", "Triangle meshes and mass properties.");
  bind_geometry(geometry);
  auto hand = m.def_submodule("hand", "Hand models and kinematics.");
  bind_hand(hand);
  auto sim = m.def_submodule("sim", "Contact simulation: auto-grasp with breakaway.");
  bind_sim(sim);
  auto quality = m.def_submodule("quality", "Grasp wrench space, epsilon and volume.");
  bind_quality(quality);
  auto physics = m.def_submodule("physics", "Physical lift test (Bullet).");
  bind_physics(physics);
  auto gp = m.def_submodule("gp", "Exact and sparse (FITC) Gaussian-process regression.");
  bind_gp(gp);
  auto belief = m.def_submodule("belief", "Particle beliefs, resampling, Metropolis moves, entropy.");
  bind_belief(belief);
  auto optim = m.def_submodule("optim", "PSO, steepest descent, simulated annealing, firefly, trust region.");
  bind_optim(optim);
  auto vision = m.def_submodule("vision", "Simulated depth camera, table segmentation, FPFH + RANSAC + ICP registration.");
  bind_vision(vision);
  auto task = m.def_submodule("task", "Task grasping (Eq. 4.1): pose densities, grasp mixtures, hand clearance.");
  bind_task(task);
}

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
void bind_touch(py::module_& m);
void bind_deform(py::module_& m);
}  // namespace bayesgrasp::bind

namespace {

struct Submodule {
  const char* name;
  const char* doc;
  void (*bind)(py::module_&);
};

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "bayesgrasp C++ core: contact simulation, grasp quality, GPs, beliefs, optimisers.";
  using namespace bayesgrasp::bind;
  // In dependency order: an option class is bound before any class that holds one (optim before
  // belief: ModelPoseOptions holds TrustRegionOptions; sim before touch).
  const Submodule submodules[] = {
      {"geometry", "Triangle meshes and mass properties.", bind_geometry},
      {"hand", "Hand models and kinematics.", bind_hand},
      {"sim", "Contact simulation: auto-grasp with breakaway.", bind_sim},
      {"quality", "Grasp wrench space, epsilon and volume.", bind_quality},
      {"physics", "Physical lift test (Bullet).", bind_physics},
      {"gp", "Exact and sparse (FITC) Gaussian-process regression.", bind_gp},
      {"optim", "PSO, steepest descent, simulated annealing, firefly, trust region.", bind_optim},
      {"belief", "Particle beliefs, resampling, Metropolis moves, entropy.", bind_belief},
      {"vision", "Simulated depth camera, table segmentation, FPFH + RANSAC + ICP registration.", bind_vision},
      {"task", "Task grasping (Eq. 4.1): pose densities, grasp mixtures, hand clearance.", bind_task},
      {"touch", "One touch (Pub. I): the executed grasp re-simulated against candidate object states.", bind_touch},
      {"deform", "Non-rigid registration: Coherent Point Drift and its displacement field.", bind_deform},
  };
  for (const Submodule& s : submodules) {
    py::module_ sub = m.def_submodule(s.name, s.doc);
    s.bind(sub);
  }
}

// Bindings for the physics concept (to be written).
#include <pybind11/pybind11.h>

namespace bayesgrasp::bind {
void bind_physics(pybind11::module_& m) {}
}  // namespace bayesgrasp::bind

// Bindings for the sim concept (to be written).
#include <pybind11/pybind11.h>

namespace bayesgrasp::bind {
void bind_sim(pybind11::module_& m) {}
}  // namespace bayesgrasp::bind

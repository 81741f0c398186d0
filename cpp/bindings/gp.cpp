// Bindings for the gp concept (to be written).
#include <pybind11/pybind11.h>

namespace bayesgrasp::bind {
void bind_gp(pybind11::module_& m) {}
}  // namespace bayesgrasp::bind

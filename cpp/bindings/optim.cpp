// Bindings for the optim concept (to be written).
#include <pybind11/pybind11.h>

namespace bayesgrasp::bind {
void bind_optim(pybind11::module_& m) {}
}  // namespace bayesgrasp::bind

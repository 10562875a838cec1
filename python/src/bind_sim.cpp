// Part 2 of issue 17 owns this file (python/README.md).
#include "bindings.hpp"

namespace lidarloop::python {

void BindSim(pybind11::module_& /*m*/) {}

}  // namespace lidarloop::python

// The extension lidarloop._lidarloop: one Bind<Area> per area (bindings.hpp). The Python package
// python/lidarloop re-exports it; docs/python.md describes the API.
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_lidarloop, m) {
    namespace python = lidarloop::python;
    m.doc() = "lidarloop: loop closure detection in 3-D LiDAR scans (C++ core)";
    m.attr("__version__") = LIDARLOOP_VERSION;
    // Errors first: every later binding raises them.
    python::BindErrors(m);
    python::BindIo(m);
    python::BindDescriptors(m);
    python::BindPipeline(m);
    python::BindTiming(m);
    python::BindRegistration(m);
    python::BindPosegraph(m);
    python::BindEval(m);
    python::BindSim(m);
    python::BindApp(m);
}

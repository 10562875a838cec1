// The extension lidarloop._lidarloop: one Bind<Area> per area (bindings.hpp). The Python package
// python/lidarloop re-exports it; docs/python.md describes the API.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_lidarloop, m) {
    namespace py = pybind11;
    namespace python = lidarloop::python;
    m.doc() = "lidarloop: loop closure detection in 3-D LiDAR scans (C++ core)";
    m.attr("__version__") = LIDARLOOP_VERSION;
    // pybind11 imports NumPy's C API lazily, inside a C++ function-local static, at the first
    // array it makes. When that happens in a worker thread, the import releases the GIL while the
    // static's guard is held; the next thread blocks on the guard holding the GIL: a deadlock
    // (issue 25). Here, at import, only one thread runs.
    py::module_::import("numpy");
    py::detail::npy_api::get();
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

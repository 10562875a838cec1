#pragma once

#include <pybind11/pybind11.h>

namespace lidarloop::python {

// One function per area, each defined in bind_<area>.cpp and called once by module.cpp. An area
// adds its classes and functions to the extension `m` (lidarloop._lidarloop); the package
// re-exports them from python/lidarloop/<area>.py (python/README.md).

/// lidarloop.Error and its subclasses, and the translation of the C++ errors into them. Called
/// first, so that every binding raises them.
void BindErrors(pybind11::module_& m);

/// Reading scans, poses and datasets.
void BindIo(pybind11::module_& m);

/// describe(), Descriptor, distances, method names, the effective config.
void BindDescriptors(pybind11::module_& m);

/// The descriptor database, its nearest-neighbour index, the online loop detector.
void BindPipeline(pybind11::module_& m);

/// Private C++ timings for bench/python_overhead.py.
void BindTiming(pybind11::module_& m);

/// Part 2 of issue 17 (registration, pose graph, evaluation, simulator, run layer).
void BindRegistration(pybind11::module_& m);
void BindPosegraph(pybind11::module_& m);
void BindEval(pybind11::module_& m);
void BindSim(pybind11::module_& m);
void BindApp(pybind11::module_& m);

}  // namespace lidarloop::python

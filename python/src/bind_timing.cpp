// Private helpers of bench/python_overhead.py: the same C++ calls that describe() and distance()
// make, timed in C++ in the same process on the same data, so that the benchmark can tell what
// calling through Python adds. Not part of the API (leading underscore, no stubs).
#include <chrono>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "conversions.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"
#include "run_config.hpp"

namespace lidarloop::python {
namespace {

using Clock = std::chrono::steady_clock;

// Seconds per call of `call`, the fastest of `rounds` rounds of `repeats` calls (the least
// disturbed by other work on the machine, as timeit's recommendation for Python).
template <typename Call>
double FastestSecondsPerCall(int repeats, int rounds, Call&& call) {
    double best = 1e300;
    for (int round = 0; round < rounds; ++round) {
        const auto start = Clock::now();
        for (int i = 0; i < repeats; ++i) call();
        const std::chrono::duration<double> elapsed = Clock::now() - start;
        best = std::min(best, elapsed.count() / repeats);
    }
    return best;
}

}  // namespace

void BindTiming(py::module_& m) {
    m.def(
        "_cpp_describe_seconds",
        [](const py::object& points, const std::string& method, int repeats, int rounds) {
            const core::PointCloud cloud = PointsFromArray(points, true);
            const io::RunConfig run = ResolveRunConfig(py::none(), method);
            py::gil_scoped_release release;
            return FastestSecondsPerCall(repeats, rounds, [&] {
                const core::Descriptor descriptor =
                    pipeline::ComputeDescriptor(cloud, run.descriptor);
                // Keep the result observable so the call is not optimised away.
                asm volatile("" : : "g"(&descriptor) : "memory");
            });
        },
        py::arg("points"), py::arg("method"), py::arg("repeats"), py::arg("rounds"));
    m.def(
        "_cpp_distance_seconds",
        [](const core::Descriptor& a, const core::Descriptor& b, int repeats, int rounds) {
            py::gil_scoped_release release;
            volatile double sink = 0.0;
            const double seconds = FastestSecondsPerCall(
                repeats, rounds, [&] { sink = sink + pipeline::DescriptorDistance(a, b); });
            return seconds;
        },
        py::arg("a"), py::arg("b"), py::arg("repeats"), py::arg("rounds"));
}

}  // namespace lidarloop::python

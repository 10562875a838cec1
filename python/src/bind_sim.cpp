// The simulator (lidarloop::sim, app::WriteSimulation): synthetic LiDAR sequences with
// ground-truth and drifting odometry poses, as arrays or written in the KITTI layout.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "conversions.hpp"
#include "lidarloop/app/simulation.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/sim/odometry_drift.hpp"
#include "lidarloop/sim/simulator.hpp"
#include "part2_helpers.hpp"

namespace lidarloop::python {
namespace {

using sim::SimulationConfig;
using sim::Simulator;

template <typename T>
constexpr const char* KindOf() {
    if constexpr (std::is_integral_v<T>) {
        return sizeof(T) == 4 ? "a 32-bit integer" : "a 64-bit integer";
    } else {
        return "a number";
    }
}

// The option `name` of the keywords, removed from them; a value of the wrong type or out of the
// C++ type's range is a TypeError naming the option (pybind11's own says neither).
template <typename T>
std::optional<T> Take(py::dict& options, const char* name) {
    if (!options.contains(name)) return std::nullopt;
    const py::object value = options[name];
    PyDict_DelItemString(options.ptr(), name);
    if (value.is_none()) return std::nullopt;
    try {
        return value.cast<T>();
    } catch (const py::cast_error&) {
        throw py::type_error(std::string(name) + " must be " + KindOf<T>() + ", got " +
                             py::repr(value).cast<std::string>());
    }
}

// Drives `positions` ((N, 3) positions or (N, 4, 4) poses, of which the positions) instead of
// the route, as `lidarloop simulate --trajectory`.
std::vector<Eigen::Vector3d> TrajectoryFrom(const py::handle& positions) {
    CheckFloatArray(positions, "trajectory");
    const auto a = py::array_t<double, py::array::forcecast>::ensure(positions);
    std::vector<Eigen::Vector3d> trajectory;
    if (a.ndim() == 3) {
        for (const core::Transform& T : TransformsFromArray(positions, "trajectory"))
            trajectory.push_back(T.translation());
        return trajectory;
    }
    if (a.ndim() != 2 || a.shape(1) != 3)
        throw ShapeError("trajectory must have shape (N, 3) or (N, 4, 4)");
    for (py::ssize_t i = 0; i < a.shape(0); ++i)
        trajectory.emplace_back(a.at(i, 0), a.at(i, 1), a.at(i, 2));
    return trajectory;
}

// The SimulationConfig the keywords name, as `lidarloop simulate` builds it from its flags
// (cli/simulate.cpp): names parsed, the sensor's and route's own values unless given, the
// odometry noise scaled by `drift` (sim::ScaledOdometry). Unknown keywords are an error.
SimulationConfig ConfigFrom(const std::optional<std::string>& scene,
                            const std::optional<std::string>& route,
                            const std::optional<std::string>& sensor,
                            std::optional<long long> scans, std::optional<std::uint64_t> seed,
                            const py::kwargs& kwargs) {
    SimulationConfig config;
    if (scene) config.scene = sim::ParseSceneType(*scene);
    if (route) config.route.type = sim::ParseRouteType(*route);
    if (sensor) config.sensor.model = sim::ParseSensorModel(*sensor);
    if (scans) {
        if (*scans < 1) throw core::ConfigError("scans must be >= 1");
        config.scans = static_cast<std::size_t>(*scans);
    }
    if (seed) config.seed = *seed;
    py::dict options = py::dict(kwargs);
    config.sensor.noise_m = Take<double>(options, "noise_m").value_or(config.sensor.noise_m);
    config.sensor.dropout = Take<double>(options, "dropout").value_or(config.sensor.dropout);
    config.sensor.horizontal_steps = Take<int>(options, "horizontal_steps");
    config.sensor.min_range_m = Take<double>(options, "min_range_m");
    config.sensor.max_range_m = Take<double>(options, "max_range_m");
    config.sensor.mount_height_m = Take<double>(options, "mount_height_m");
    config.sensor.scan_period_s = Take<double>(options, "scan_period_s");
    auto& r = config.route;
    r.spacing_min_m = Take<double>(options, "spacing_min_m").value_or(r.spacing_min_m);
    r.spacing_max_m = Take<double>(options, "spacing_max_m").value_or(r.spacing_max_m);
    r.uturn_blocks = Take<int>(options, "uturn_blocks").value_or(r.uturn_blocks);
    config.front_end.keep_every =
        Take<std::int64_t>(options, "keep_every").value_or(config.front_end.keep_every);
    if (const auto drift = Take<double>(options, "drift"))
        config.odometry = sim::ScaledOdometry(config.odometry, *drift);
    if (options.contains("trajectory")) {
        // None keeps the route, as None keeps every other option's default.
        if (!options["trajectory"].is_none()) {
            config.trajectory = TrajectoryFrom(options["trajectory"]);
            config.scans = config.trajectory.size();
        }
        PyDict_DelItemString(options.ptr(), "trajectory");
    }
    if (!options.empty()) {
        throw py::type_error("unknown simulation options: " +
                             py::str(options.attr("keys")()).cast<std::string>());
    }
    config.Validate();
    return config;
}

std::unique_ptr<Simulator> MakeSimulator(const SimulationConfig& config) {
    py::gil_scoped_release release;
    return std::make_unique<Simulator>(config);
}

py::tuple PosesOf(const Simulator& simulator, bool odometry) {
    std::vector<core::StampedPose> poses;
    {
        py::gil_scoped_release release;
        if (odometry) {
            poses = simulator.OdometryPoses(0, simulator.size());
        } else {
            for (std::size_t i = 0; i < simulator.size(); ++i)
                poses.push_back(simulator.GroundTruthPose(i));
        }
    }
    return PosesToArrays(poses);
}

void BindSimulator(py::module_& m) {
    py::class_<Simulator>(
        m, "Simulator",
        "A synthetic LiDAR sequence computed on demand. World frame z up; scans in the sensor "
        "frame (x forward, y left, z up), metres; scan i at time i * scan_period_s. Same "
        "arguments, same sequence (as `lidarloop simulate`).")
        .def(py::init([](const std::optional<std::string>& scene,
                         const std::optional<std::string>& route,
                         const std::optional<std::string>& sensor, std::optional<long long> scans,
                         std::optional<std::uint64_t> seed, const py::kwargs& kwargs) {
                 return MakeSimulator(ConfigFrom(scene, route, sensor, scans, seed, kwargs));
             }),
             py::arg("scene") = py::none(), py::arg("route") = py::none(),
             py::arg("sensor") = py::none(), py::arg("scans") = py::none(),
             py::arg("seed") = py::none(),
             "scene: urban | rural | mine | indoor (default urban); route: uturn | figure8 | "
             "grid (default uturn); sensor: hdl64 | vlp16 | tilt180 | hdl32 | ouster64-wide | "
             "livox-avia (default hdl64); scans (default 100); seed (default 1). Options as "
             "`lidarloop simulate`'s flags: noise_m, dropout, horizontal_steps, min_range_m, "
             "max_range_m, mount_height_m, scan_period_s, spacing_min_m, spacing_max_m, "
             "uturn_blocks, keep_every (every N-th point of a scan kept), drift (factor on the "
             "odometry noise), trajectory ((N, 3) positions or (N, 4, 4) poses to drive).")
        .def_static(
            "demo", [] { return MakeSimulator(sim::DemoConfig()); },
            "The sequence of `lidarloop demo` (320 VLP-16 scans, urban grid)")
        .def("__len__", &Simulator::size)
        .def_property_readonly("scene",
                               [](const Simulator& s) { return sim::ToString(s.config().scene); })
        .def_property_readonly(
            "route", [](const Simulator& s) { return sim::ToString(s.config().route.type); })
        .def_property_readonly("sensor",
                               [](const Simulator& s) { return sim::ToString(s.sensor().model); })
        .def_property_readonly("seed", [](const Simulator& s) { return s.config().seed; })
        .def_property_readonly("scan_period_s",
                               [](const Simulator& s) { return s.sensor().scan_period_s; })
        .def_property_readonly("mount_height_m",
                               [](const Simulator& s) { return s.sensor().mount_height_m; })
        .def(
            "scan",
            [](const Simulator& s, std::size_t index) {
                if (index >= s.size()) throw py::index_error("scan index out of range");
                core::PointCloud cloud;
                {
                    py::gil_scoped_release release;
                    cloud = s.Scan(index);
                }
                return PointsToArray(std::move(cloud));
            },
            py::arg("index"), "(N, 3) float32 points of scan `index`, sensor frame, metres")
        .def(
            "ground_truth_poses", [](const Simulator& s) { return PosesOf(s, false); },
            "(times_s (N,), T_world_sensor (N, 4, 4)) of every scan")
        .def(
            "odometry_poses", [](const Simulator& s) { return PosesOf(s, true); },
            "(times_s (N,), T_world_sensor (N, 4, 4)): the drifting odometry, equal to the "
            "ground truth at scan 0");
}

// A callback that raised stops the writing (the sequence is then not finished, and readers
// refuse it) instead of letting it run on unobserved.
app::Progress StopOnFailure(const PythonProgress& python_progress) {
    const app::Progress forward = python_progress.Callback();
    if (!forward) return {};
    return
        [forward, &python_progress](const std::string& stage, std::size_t done, std::size_t total) {
            forward(stage, done, total);
            const py::gil_scoped_acquire gil;
            if (python_progress.Failed())
                throw core::Error("the progress callback raised an exception");
        };
}

void BindWriteSimulation(py::module_& m) {
    py::class_<app::SimulationSummary>(m, "SimulationSummary")
        .def_readonly("mean_points", &app::SimulationSummary::mean_points)
        .def_readonly("min_points", &app::SimulationSummary::min_points)
        .def_readonly("max_points", &app::SimulationSummary::max_points)
        .def_readonly("revisited_scans", &app::SimulationSummary::revisited_scans,
                      "scans within 4 m of a scan 30+ earlier")
        .def_readonly("seconds", &app::SimulationSummary::seconds);
    m.def(
        "write_simulation",
        [](const Simulator& simulator, const std::filesystem::path& out, bool overwrite,
           int threads, const py::object& progress) {
            const PythonProgress python_progress(progress);
            app::SimulationSummary summary;
            try {
                py::gil_scoped_release release;
                summary = app::WriteSimulation(simulator, out,
                                               {"lidarloop.write_simulation", {}, overwrite},
                                               threads, StopOnFailure(python_progress));
            } catch (const core::Error&) {
                python_progress.Rethrow();  // the callback's own exception, when it raised one
                throw;
            }
            python_progress.Rethrow();
            return summary;
        },
        py::arg("simulator"), py::arg("out"), py::arg("overwrite") = false, py::arg("threads") = 0,
        py::arg("progress") = py::none(),
        "Writes the whole sequence into `out` in the KITTI layout (velodyne/*.bin, poses.txt, "
        "times.txt, poses_odometry.txt, simulation.yaml), as `lidarloop simulate`, by the "
        "results-folder rule (docs/cli.md): a folder that lidarloop did not write is replaced "
        "only with overwrite=True, an interrupted run leaves the earlier sequence. "
        "progress(stage, done, total) is called from worker threads, one call at a time, with done "
        "rising to total.");
}

}  // namespace

void BindSim(py::module_& m) {
    BindSimulator(m);
    BindWriteSimulation(m);
}

}  // namespace lidarloop::python

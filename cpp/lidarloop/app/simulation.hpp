#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>

#include "lidarloop/app/progress.hpp"
#include "lidarloop/app/run_folder.hpp"
#include "lidarloop/sim/simulator.hpp"

namespace lidarloop::app {

/// A scan revisits a place when it lies within this distance of a scan at least kRevisitGap
/// scans earlier (4 m catches the lane-offset revisits, 3.5 m apart in town).
inline constexpr double kRevisitDistance_m = 4.0;
inline constexpr std::size_t kRevisitGap = 30;

struct SimulationSummary {
    std::size_t mean_points = 0;
    std::size_t min_points = 0;
    std::size_t max_points = 0;
    std::size_t revisited_scans = 0;  ///< see kRevisitDistance_m
    double seconds = 0.0;
};

/// Writes the whole sequence of `simulator` to `out` in KITTI layout (velodyne/*.bin, poses.txt,
/// times.txt, poses_odometry.txt) with simulation.yaml, scans in parallel on `threads` threads
/// (0: all cores), by the results-folder rule (RunFolder, with `run` as its command line, inputs
/// and overwrite; the kind is always a dataset): staged and swapped in whole, so that an
/// interrupted run leaves the earlier sequence, or a run.json that makes readers refuse the
/// folder. Throws io::WriteError.
SimulationSummary WriteSimulation(const sim::Simulator& simulator, const std::filesystem::path& out,
                                  RunInfo run, int threads, const Progress& progress = {});

/// The demo sequence (sim::DemoConfig) in `folder`: reused when `folder` holds a complete
/// sequence that lidarloop wrote, generated otherwise (then `generated` is set) under the
/// results-folder rule of `run`.
struct DemoSequence {
    std::filesystem::path folder;
    std::optional<SimulationSummary> generated;
};
DemoSequence PrepareDemoSequence(const std::filesystem::path& folder, RunInfo run,
                                 const Progress& progress = {});

}  // namespace lidarloop::app

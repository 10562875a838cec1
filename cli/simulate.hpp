#pragma once

#include <cstddef>
#include <filesystem>

#include "lidarloop/sim/simulator.hpp"

namespace lidarloop::cli {

struct SimulationSummary {
    std::size_t mean_points = 0;
    std::size_t min_points = 0;
    std::size_t max_points = 0;
    std::size_t revisited_scans = 0;  ///< within 4 m of a scan at least 30 scans earlier
    double seconds = 0.0;
};

/// Writes the whole sequence of `simulator` to `out` in KITTI layout (velodyne/*.bin, poses.txt,
/// times.txt, poses_odometry.txt) with simulation.yaml, scans in parallel.
SimulationSummary WriteSimulation(const sim::Simulator& simulator, const std::filesystem::path& out,
                                  bool overwrite, int threads, bool quiet);

}  // namespace lidarloop::cli

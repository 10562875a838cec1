#pragma once

#include <filesystem>

#include "lidarloop/app/simulation.hpp"
#include "lidarloop/io/dataset.hpp"

namespace lidarloop::test {

/// A short demo-town sequence (200 VLP-16 scans, thinned) in KITTI layout in `folder`, with
/// poses: small enough for a run-layer test, with revisits.
inline io::Dataset SmallSequence(const std::filesystem::path& folder) {
    sim::SimulationConfig config = sim::DemoConfig();
    config.scans = 200;
    config.sensor.horizontal_steps = 360;
    app::WriteSimulation(sim::Simulator(config), folder, /*run=*/{}, /*threads=*/0);
    return io::OpenDataset(folder);
}

}  // namespace lidarloop::test

#pragma once

#include <cstdint>
#include <cstdlib>
#include <filesystem>

#include "lidarloop/app/simulation.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/layout_signature.hpp"
#include "lidarloop/registration/verification.hpp"

namespace lidarloop::test {

/// Names a SmallSequence written beforehand: ctest's app_tests.small_sequence fixture
/// (tests/cpp/app/CMakeLists.txt) sets it for the run-layer tests, which copy that folder instead
/// of simulating the sequence again (most of such a test's time under the sanitizers).
inline constexpr const char* kSmallSequenceVariable = "LIDARLOOP_SMALL_SEQUENCE";

/// Simulates SmallSequence's scans and poses into `folder`, with the demo's world and noise or
/// another seed's.
inline void WriteSmallSequence(const std::filesystem::path& folder,
                               std::uint64_t seed = sim::DemoConfig().seed) {
    sim::SimulationConfig config = sim::DemoConfig();
    config.scans = 200;
    config.sensor.horizontal_steps = 360;
    config.seed = seed;
    app::WriteSimulation(sim::Simulator(config), folder, /*run=*/{}, /*threads=*/0);
}

/// A short demo-town sequence (200 VLP-16 scans, thinned) in KITTI layout in `folder`, with
/// poses: small enough for a run-layer test, with revisits. A copy of the folder that
/// kSmallSequenceVariable names, when set; simulated otherwise.
inline io::Dataset SmallSequence(const std::filesystem::path& folder) {
    const char* written = std::getenv(kSmallSequenceVariable);
    if (written != nullptr && *written != '\0') {
        std::filesystem::copy(written, folder, std::filesystem::copy_options::recursive);
    } else {
        WriteSmallSequence(folder);
    }
    return io::OpenDataset(folder);
}

/// SmallSequence's route through another seed's town, with its own noise: always simulated.
inline io::Dataset OtherSmallSequence(const std::filesystem::path& folder, std::uint64_t seed) {
    WriteSmallSequence(folder, seed);
    return io::OpenDataset(folder);
}

/// A pair registered on its own, its scans kept as detect keeps them (compact), its coarse search
/// within the yaws their layouts suggest, as detect and bench search without odometry.
inline registration::Verification VerifyAsKept(const core::PointCloud& query,
                                               const core::PointCloud& match,
                                               const registration::VerificationConfig& config) {
    const auto kept = [&](const core::PointCloud& scan) {
        return registration::CompactPreparedScan(registration::PrepareScan(scan, config.reduction));
    };
    const registration::CompactPreparedScan kept_query = kept(query), kept_match = kept(match);
    const registration::YawWindow yaws =
        registration::LayoutYawWindow(kept_query.layout(), kept_match.layout(), config.coarse);
    const registration::PreparedScan prepared_query = kept_query.Expand();
    return registration::Verify(
        prepared_query, registration::CoarseQuery(*prepared_query.structure, config.coarse, {yaws}),
        kept_match.Expand(), config, {}, yaws);
}

}  // namespace lidarloop::test

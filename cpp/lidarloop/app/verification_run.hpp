#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarloop/app/progress.hpp"
#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/pipeline/candidate_verification.hpp"
#include "lidarloop/registration/prepared_scan.hpp"

namespace lidarloop::app {

/// Every scan of a sequence prepared for verification, filled while the scans are described.
struct PreparedScans {
    std::vector<registration::PreparedScan> scans;  ///< by scan index; empty for skipped scans
    std::vector<double> prepare_seconds;            ///< per scan

    explicit PreparedScans(std::size_t count) : scans(count), prepare_seconds(count, 0.0) {}

    /// A DescribeRun::with_cloud callback that prepares scan i into scans[i] (thread-safe for
    /// distinct scans). The callback refers to this object and `reduction`.
    std::function<void(std::size_t, const core::PointCloud&)> Collector(
        const registration::ScanReductionConfig& reduction);
    /// Heap bytes of the prepared scans, per scan (skipped scans excluded).
    std::vector<double> BytesPerScan() const;
};

/// pipeline::VerifyQueries over `queries`, telling `progress` as stage "verifying".
pipeline::VerificationTimes VerifyAll(std::vector<pipeline::LoopQuery>& queries,
                                      const PreparedScans& prepared,
                                      const pipeline::DetectorConfig& detector,
                                      const core::Method& method, const Progress& progress);

/// The figures of a verification run for timings.json: per scan preparation (ms) and memory
/// (bytes), per query coarse images (ms), per candidate pair (ms), counts.
nlohmann::json VerificationTimingsJson(const PreparedScans& prepared,
                                       const pipeline::VerificationTimes& times);

}  // namespace lidarloop::app

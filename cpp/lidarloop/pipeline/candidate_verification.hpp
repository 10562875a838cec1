#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/registration/prepared_scan.hpp"

namespace lidarloop::pipeline {

/// Times of one verification run, seconds.
struct VerificationTimes {
    std::vector<double> pair_seconds;   ///< per registered candidate pair (coarse search + ICP)
    std::vector<double> query_seconds;  ///< per query: its coarse search images (shared by pairs)
};

/// Registers the candidates of `query` to it (registration::Verify) and fills
/// query.verifications and query.accepted. `scan_of(i)` gives scan i prepared with
/// detector.verification.reduction. A candidate whose distance fails an explicitly set
/// detector.threshold is not registered (reason kPruned). Appends to `times` when given.
void VerifyQuery(LoopQuery& query,
                 const std::function<const registration::PreparedScan&(std::size_t)>& scan_of,
                 const DetectorConfig& detector, const core::Method& method,
                 VerificationTimes* times = nullptr);

/// VerifyQuery for every query that has candidates (in parallel unless told otherwise);
/// `scans[i]` is scan i prepared. `progress(done, total)` is called from worker threads.
VerificationTimes VerifyQueries(std::vector<LoopQuery>& queries,
                                const std::vector<registration::PreparedScan>& scans,
                                const DetectorConfig& detector, const core::Method& method,
                                Execution execution = Execution::kParallel,
                                const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace lidarloop::pipeline

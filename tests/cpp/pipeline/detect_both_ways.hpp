#pragma once

// A sequence's queries as both detectors judge them, for tests of the rules they share.

#include <vector>

#include "lidarloop/pipeline/candidate_verification.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

namespace lidarloop::test {

struct Detections {
    std::vector<pipeline::LoopQuery> online;   ///< LoopDetector::Process, scan by scan
    std::vector<pipeline::LoopQuery> offline;  ///< the similarity matrix, then VerifyQueries
};

/// `scans` (one second apart) described with range and detected online and offline by
/// `detector`.
inline Detections DetectBothWays(const std::vector<core::PointCloud>& scans,
                                 const pipeline::DetectorConfig& detector) {
    core::DescriptorConfig config;
    config.method = core::Method::kRange;
    pipeline::LoopDetector online(config, detector);
    Detections result;
    std::vector<double> times;
    for (std::size_t i = 0; i < scans.size(); ++i) {
        times.push_back(static_cast<double>(i));
        result.online.push_back(online.Process(scans[i], times.back()));
    }
    result.offline =
        pipeline::DetectFromMatrix(pipeline::ComputeSimilarityMatrix(online.database()), times,
                                   detector, core::Method::kRange);
    std::vector<registration::CompactPreparedScan> prepared;
    for (const auto& scan : scans)
        prepared.emplace_back(registration::PrepareScan(scan, detector.verification.reduction));
    pipeline::VerifyQueries(result.offline, prepared, detector, core::Method::kRange,
                            pipeline::Execution::kSerial);
    return result;
}

}  // namespace lidarloop::test

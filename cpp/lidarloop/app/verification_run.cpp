#include "lidarloop/app/verification_run.hpp"

#include "lidarloop/app/results_folder.hpp"

namespace lidarloop::app {

std::function<void(std::size_t, const core::PointCloud&)> PreparedScans::Collector(
    const registration::ScanReductionConfig& reduction) {
    return [this, &reduction](std::size_t i, const core::PointCloud& cloud) {
        const Stopwatch clock;
        scans.at(i) = registration::PrepareScan(cloud, reduction);
        prepare_seconds.at(i) = clock.Seconds();
    };
}

std::vector<double> PreparedScans::BytesPerScan() const {
    std::vector<double> bytes;
    for (const auto& scan : scans) {
        if (scan.structure) bytes.push_back(static_cast<double>(scan.MemoryBytes()));
    }
    return bytes;
}

pipeline::VerificationTimes VerifyAll(std::vector<pipeline::LoopQuery>& queries,
                                      const PreparedScans& prepared,
                                      const pipeline::DetectorConfig& detector,
                                      const core::Method& method, const Progress& progress) {
    std::function<void(std::size_t, std::size_t)> tell;
    if (progress)
        tell = [&progress](std::size_t done, std::size_t n) { progress("verifying", done, n); };
    return pipeline::VerifyQueries(queries, prepared.scans, detector, method,
                                   pipeline::Execution::kParallel, tell);
}

nlohmann::json VerificationTimingsJson(const PreparedScans& prepared,
                                       const pipeline::VerificationTimes& times) {
    const auto ms = [](const std::vector<double>& seconds) { return SummaryJson(seconds, 1e3); };
    nlohmann::json json;
    json["prepare_ms_per_scan"] = ms(prepared.prepare_seconds);
    json["bytes_per_prepared_scan"] = SummaryJson(prepared.BytesPerScan());
    json["coarse_images_ms_per_query"] = ms(times.query_seconds);
    json["verify_ms_per_pair"] = ms(times.pair_seconds);
    json["pairs_verified"] = times.pair_seconds.size();
    return json;
}

}  // namespace lidarloop::app

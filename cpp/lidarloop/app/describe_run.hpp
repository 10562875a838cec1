#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "lidarloop/app/progress.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/pipeline/sequence.hpp"

namespace lidarloop::app {

/// The scans of `dataset` as a pipeline source; times from its poses, else the scan index.
/// `dataset` must outlive the source.
pipeline::ScanSource SourceOf(const io::Dataset& dataset);

/// Reads one scan file and computes its descriptor under `config`; errors name the file
/// (io::ReadError, also for a scan with nothing usable in it).
core::Descriptor DescribeScanFile(const std::filesystem::path& file,
                                  const core::DescriptorConfig& config);

/// How DescribeDataset runs.
struct DescribeRun {
    std::string stage = "describing";  ///< the stage named to `progress`
    bool skip_bad = false;  ///< unreadable scans get a placeholder instead of stopping the run
    pipeline::Execution execution = pipeline::Execution::kParallel;
    Progress progress;
    /// Also given every scan read (pipeline::DescribeOptions::with_cloud), e.g. PreparedScans.
    std::function<void(std::size_t, const core::PointCloud&)> with_cloud;
};

/// Describes every scan of `dataset` (pipeline::DescribeSequence), telling `run.progress`.
pipeline::SequenceDescriptors DescribeDataset(const io::Dataset& dataset,
                                              const core::DescriptorConfig& config,
                                              const DescribeRun& run);

/// Per-scan timings of describing a dataset (reading and describing, median and p95), in ms.
nlohmann::json DescribeTimingsJson(const pipeline::SequenceDescriptors& described);
/// DescribeTimingsJson plus the similarity matrix: per comparison in nanoseconds.
nlohmann::json TimingsJson(const pipeline::SequenceDescriptors& described, std::size_t pairs,
                           double matrix_s);

}  // namespace lidarloop::app

#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/pipeline/descriptor_database.hpp"
#include "lidarloop/pipeline/progress_counter.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

namespace lidarloop::pipeline {

/// Where the scans of a sequence come from (the io layer wires a dataset in). `load` may throw
/// core::Error (e.g. io::ReadError naming the file); it must be safe to call from several
/// threads for different indices.
struct ScanSource {
    std::size_t count = 0;
    std::function<core::PointCloud(std::size_t)> load;
    std::function<double(std::size_t)> time_s;  ///< recording time of scan i, seconds
    /// Names scan i (its file) in the message of a scan that loads but has nothing usable in it
    /// (an empty file); optional. `load`'s own errors name what they read.
    std::function<std::string(std::size_t)> name;
};

struct DescribeOptions {
    /// false: the first unreadable or unusable scan stops the run with an error naming it.
    /// true: such scans get a placeholder that matches nothing, and are listed in `skipped`.
    bool skip_bad = false;
    Execution execution = Execution::kParallel;
    /// Called after each scan with (scans done, total), from any worker thread, one call at a
    /// time with `done` rising.
    ProgressReport progress;
    /// Also called with (scan index, cloud) for every scan read and described, from any worker
    /// thread, e.g. to keep what verification needs of it; must not throw.
    std::function<void(std::size_t, const core::PointCloud&)> with_cloud;
};

struct SequenceDescriptors {
    DescriptorDatabase database;
    std::vector<double> load_seconds;      ///< per scan: reading the file
    std::vector<double> describe_seconds;  ///< per scan: computing the descriptor
    std::vector<std::string> skipped;      ///< "scan 17: <reason>" for every skipped scan
};

/// Describes every scan of `source` (in parallel with oneTBB unless told otherwise) and stores
/// the descriptors in scan order. Throws core::Error "scan <i>: <reason>" on the first bad scan
/// unless options.skip_bad.
SequenceDescriptors DescribeSequence(const ScanSource& source, const core::DescriptorConfig& config,
                                     const DescribeOptions& options = {});

}  // namespace lidarloop::pipeline

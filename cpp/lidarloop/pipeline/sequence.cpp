#include "lidarloop/pipeline/sequence.hpp"

#include <optional>

#include <tbb/parallel_for.h>

#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/stopwatch.hpp"

namespace lidarloop::pipeline {
namespace {

struct ScanResult {
    std::optional<core::Descriptor> descriptor;
    std::string error;
    double load_seconds = 0.0;
    double describe_seconds = 0.0;
};

core::Descriptor DescribeNamed(const ScanSource& source, std::size_t i,
                               const core::PointCloud& cloud,
                               const core::DescriptorConfig& config) {
    try {
        return ComputeDescriptor(cloud, config);
    } catch (const core::EmptyInputError& e) {
        if (!source.name) throw;
        throw core::EmptyInputError(source.name(i) + ": " + e.what());
    }
}

ScanResult DescribeOne(const ScanSource& source, const core::DescriptorConfig& config,
                       std::size_t i, const DescribeOptions& options) {
    const bool skip_bad = options.skip_bad;
    ScanResult result;
    try {
        const core::Stopwatch load_clock;
        const core::PointCloud cloud = source.load(i);
        result.load_seconds = load_clock.Seconds();
        const core::Stopwatch describe_clock;
        result.descriptor = DescribeNamed(source, i, cloud, config);
        result.describe_seconds = describe_clock.Seconds();
        if (options.with_cloud) options.with_cloud(i, cloud);
    } catch (const core::ConfigError&) {
        throw;  // a bad configuration is not a bad scan
    } catch (const core::Error& e) {
        const std::string message = "scan " + std::to_string(i) + ": " + e.what();
        if (!skip_bad) throw core::Error(message);
        result.error = message;
    }
    return result;
}

}  // namespace

SequenceDescriptors DescribeSequence(const ScanSource& source, const core::DescriptorConfig& config,
                                     const DescribeOptions& options) {
    SequenceDescriptors out{DescriptorDatabase(config), {}, {}, {}};
    std::vector<ScanResult> results(source.count);
    ProgressCounter done(options.progress, source.count);
    const auto run = [&](std::size_t i) {
        results[i] = DescribeOne(source, config, i, options);
        done.Add();
    };
    if (options.execution == Execution::kParallel) {
        tbb::parallel_for(std::size_t{0}, source.count, run);
    } else {
        for (std::size_t i = 0; i < source.count; ++i) run(i);
    }
    for (std::size_t i = 0; i < source.count; ++i) {
        const double time_s = source.time_s ? source.time_s(i) : static_cast<double>(i);
        ScanResult& r = results[i];
        out.load_seconds.push_back(r.load_seconds);
        out.describe_seconds.push_back(r.describe_seconds);
        if (r.descriptor) {
            out.database.Add(*r.descriptor, time_s);
        } else {
            out.database.AddMissing(time_s);
            out.skipped.push_back(r.error);
        }
    }
    return out;
}

}  // namespace lidarloop::pipeline

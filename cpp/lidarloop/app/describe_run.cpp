#include "lidarloop/app/describe_run.hpp"

#include <thread>

#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/scan_reader.hpp"

namespace lidarloop::app {

pipeline::ScanSource SourceOf(const io::Dataset& dataset) {
    pipeline::ScanSource source;
    source.count = dataset.size();
    source.load = [&dataset](std::size_t i) { return dataset.LoadScan(i); };
    source.time_s = [&dataset](std::size_t i) { return dataset.ScanTime(i); };
    source.name = [&dataset](std::size_t i) { return dataset.ScanPath(i).string(); };
    return source;
}

core::Descriptor DescribeScanFile(const std::filesystem::path& file,
                                  const core::DescriptorConfig& config) {
    const core::PointCloud cloud = io::ReadScan(file);
    try {
        return pipeline::ComputeDescriptor(cloud, config);
    } catch (const core::EmptyInputError& e) {
        throw io::ReadError(file, e.what());
    }
}

pipeline::SequenceDescriptors DescribeDataset(const io::Dataset& dataset,
                                              const core::DescriptorConfig& config,
                                              const DescribeRun& run) {
    pipeline::DescribeOptions options;
    options.skip_bad = run.skip_bad;
    options.execution = run.execution;
    options.with_cloud = run.with_cloud;
    options.progress = StageReport(run.progress, run.stage);
    return pipeline::DescribeSequence(SourceOf(dataset), config, options);
}

namespace {

// How much work each scan's descriptor was (e.g. NDT rotation candidates and classified cells),
// under the method's name, so that a time per scan can be read against what it covered.
nlohmann::json WorkJson(const pipeline::DescriptorDatabase& database) {
    nlohmann::json json;
    for (const pipeline::WorkFigure& figure : database.Work())
        json[figure.name] = SummaryJson(figure.values);
    return json;
}

}  // namespace

nlohmann::json DescribeTimingsJson(const pipeline::SequenceDescriptors& described) {
    const auto ms = [](std::vector<double> seconds, double q) {
        return 1e3 * Quantile(std::move(seconds), q);
    };
    nlohmann::json json;
    json["scans"] = described.database.size();
    json["threads"] = std::thread::hardware_concurrency();
    json["describe_ms_per_scan"] = {{"median", ms(described.describe_seconds, 0.5)},
                                    {"p95", ms(described.describe_seconds, 0.95)}};
    json["describe_ms_per_scan"]["max"] = ms(described.describe_seconds, 1.0);
    json["load_ms_per_scan"] = {{"median", ms(described.load_seconds, 0.5)},
                                {"p95", ms(described.load_seconds, 0.95)}};
    const nlohmann::json work = WorkJson(described.database);
    if (!work.empty()) json[core::ToString(described.database.method())] = work;
    return json;
}

nlohmann::json TimingsJson(const pipeline::SequenceDescriptors& described, std::size_t pairs,
                           double matrix_s) {
    nlohmann::json json = DescribeTimingsJson(described);
    json["similarity_matrix_s"] = matrix_s;
    json["pairs"] = pairs;
    json["ns_per_comparison_wall"] = pairs > 0 ? 1e9 * matrix_s / static_cast<double>(pairs) : 0.0;
    return json;
}

}  // namespace lidarloop::app

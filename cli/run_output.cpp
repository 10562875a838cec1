#include "run_output.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <thread>

#include "dataset_options.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/summary.hpp"
#include "lidarloop/io/read_error.hpp"
#include "progress.hpp"

namespace lidarloop::cli {

void DetectionOptions::AddTo(CLI::App& command) {
    threshold_option_ = command.add_option(
        "--threshold", threshold_, "tau (height, range) or t_d (ndt); default from the config");
    min_gap_option_ = command.add_option("--min-gap", min_gap_,
                                         "S: candidates at least this far back (default 30 scans)");
    command.add_option("--min-gap-unit", min_gap_unit_, "unit of --min-gap: scans | seconds");
    top_k_option_ = command.add_option("--top-k", top_k_, "candidates per query scan");
}

void DetectionOptions::ApplyTo(io::RunConfig& config) const {
    if (*threshold_option_) {
        (config.descriptor.method == core::Method::kNdt ? config.descriptor.ndt.threshold
                                                        : config.descriptor.histogram.threshold) =
            threshold_;
    }
    if (*min_gap_option_) config.detection.min_gap.value = min_gap_;
    if (!min_gap_unit_.empty())
        config.detection.min_gap.unit = core::ParseMinGapUnit(min_gap_unit_);
    if (*top_k_option_) config.detection.top_k = top_k_;
    config.Validate();
}

void RequireTimesForSeconds(const io::RunConfig& config, const io::Dataset& dataset) {
    if (config.detection.min_gap.unit == core::MinGap::Unit::kSeconds && !dataset.HasPoses()) {
        throw core::ConfigError("a minimum gap in seconds needs scan times, and " +
                                dataset.root().string() +
                                " has no poses; give --poses or a gap in scans");
    }
}

std::filesystem::path PrepareOutputFolder(const std::string& folder) {
    const std::filesystem::path path(folder);
    std::error_code ec;
    std::filesystem::create_directories(path, ec);
    if (ec || !std::filesystem::is_directory(path)) {
        throw io::WriteError(path, "cannot create the output folder" +
                                       (ec ? " (" + ec.message() + ")" : std::string()));
    }
    return path;
}

double Quantile(std::vector<double> values, double q) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    return eval::Quantile(values, q);
}

pipeline::SequenceDescriptors DescribeDataset(const io::Dataset& dataset,
                                              const core::DescriptorConfig& config,
                                              const DescribeRun& run) {
    pipeline::DescribeOptions options;
    options.skip_bad = run.skip_bad;
    options.execution = run.execution;
    ProgressBar bar(run.label, run.quiet);
    options.progress = [&](std::size_t done, std::size_t n) { bar.Update(done, n); };
    return pipeline::DescribeSequence(SourceOf(dataset), config, options);
}

namespace {

// How much work the NDT descriptors of a sequence were: rotation candidates (section II-C, one
// descriptor each) and classified cells per valid scan, so that a time per scan can be read
// against what it covered.
nlohmann::json NdtSetSizesJson(const pipeline::DescriptorDatabase& database) {
    std::vector<double> candidates;
    std::vector<double> cells;
    for (std::size_t i = 0; i < database.size(); ++i) {
        if (!database.IsValid(i)) continue;
        const core::NdtDescriptorSet& set = database.ndt_sets()[i];
        candidates.push_back(static_cast<double>(set.descriptors.size()));
        cells.push_back(set.descriptors.empty() ? 0.0 : set.descriptors.front().total);
    }
    const auto summary = [](const std::vector<double>& values) {
        return nlohmann::json{{"median", Quantile(values, 0.5)},
                              {"p95", Quantile(values, 0.95)},
                              {"max", Quantile(values, 1.0)}};
    };
    return {{"rotation_candidates_per_scan", summary(candidates)},
            {"classified_cells_per_scan", summary(cells)}};
}

}  // namespace

nlohmann::json DescribeTimingsJson(const pipeline::SequenceDescriptors& described) {
    const auto ms = [](std::vector<double> seconds, double q) {
        return 1e3 * Quantile(seconds, q);
    };
    nlohmann::json json;
    json["scans"] = described.database.size();
    json["threads"] = std::thread::hardware_concurrency();
    json["describe_ms_per_scan"] = {{"median", ms(described.describe_seconds, 0.5)},
                                    {"p95", ms(described.describe_seconds, 0.95)}};
    json["describe_ms_per_scan"]["max"] = ms(described.describe_seconds, 1.0);
    json["load_ms_per_scan"] = {{"median", ms(described.load_seconds, 0.5)},
                                {"p95", ms(described.load_seconds, 0.95)}};
    if (!described.database.ndt_sets().empty()) json["ndt"] = NdtSetSizesJson(described.database);
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

void WriteJson(const std::filesystem::path& file, const nlohmann::json& json) {
    std::ofstream out(file);
    out << json.dump(2) << "\n";
    if (!out) throw io::WriteError(file, "writing failed");
}

void WriteSkipped(const std::filesystem::path& folder, const std::vector<std::string>& skipped) {
    if (skipped.empty()) return;
    std::ofstream out(folder / "skipped.txt");
    for (const std::string& line : skipped) out << line << "\n";
    if (!out) throw io::WriteError(folder / "skipped.txt", "writing failed");
}

}  // namespace lidarloop::cli

#pragma once

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/pipeline/sequence.hpp"

namespace lidarloop::cli {

/// The detection flags: --threshold, --min-gap, --min-gap-unit, --top-k.
class DetectionOptions {
public:
    void AddTo(CLI::App& command);
    /// Overrides the keys the flags name; --threshold sets the active method's threshold.
    void ApplyTo(io::RunConfig& config) const;

private:
    double threshold_ = 0.0;
    double min_gap_ = 0.0;
    std::string min_gap_unit_;
    int top_k_ = 0;
    CLI::Option* threshold_option_ = nullptr;
    CLI::Option* min_gap_option_ = nullptr;
    CLI::Option* top_k_option_ = nullptr;
};

/// A gap in seconds needs real scan times; fail early when the dataset has none.
void RequireTimesForSeconds(const io::RunConfig& config, const io::Dataset& dataset);

/// Creates `folder` (and parents); WriteError when that is impossible.
std::filesystem::path PrepareOutputFolder(const std::string& folder);

/// Wall-clock seconds since construction.
class Stopwatch {
public:
    double Seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }

private:
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// The q-quantile (0..1) of `values` (eval::Quantile after sorting); 0 for an empty list.
double Quantile(std::vector<double> values, double q);

/// How DescribeDataset runs.
struct DescribeRun {
    std::string label = "describing";  ///< progress bar text
    bool skip_bad = false;
    bool quiet = false;  ///< no progress bar
    pipeline::Execution execution = pipeline::Execution::kParallel;
};

/// Describes every scan of `dataset` (pipeline::DescribeSequence) with a progress bar on a
/// terminal.
pipeline::SequenceDescriptors DescribeDataset(const io::Dataset& dataset,
                                              const core::DescriptorConfig& config,
                                              const DescribeRun& run);

/// Per-scan timings of describing a dataset (reading and describing, median and p95), in ms.
nlohmann::json DescribeTimingsJson(const pipeline::SequenceDescriptors& described);
/// DescribeTimingsJson plus the similarity matrix: per comparison in nanoseconds.
nlohmann::json TimingsJson(const pipeline::SequenceDescriptors& described, std::size_t pairs,
                           double matrix_s);

void WriteJson(const std::filesystem::path& file, const nlohmann::json& json);
/// Writes skipped.txt (one line per skipped scan) when any scan was skipped.
void WriteSkipped(const std::filesystem::path& folder, const std::vector<std::string>& skipped);

}  // namespace lidarloop::cli

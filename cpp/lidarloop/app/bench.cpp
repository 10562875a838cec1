#include "lidarloop/app/bench.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <limits>
#include <optional>
#include <random>

#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/pipeline/histogram_index.hpp"
#include "lidarloop/pipeline/histogram_method.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

namespace lidarloop::app {
namespace {

double PeakMemoryMiB() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// Times `queries` top-1 searches of stored scans (as queries) against the whole database,
// through the index when there is one, and by comparing every scan.
nlohmann::json TimeQueries(const pipeline::DescriptorDatabase& database, std::size_t queries) {
    nlohmann::json json;
    std::vector<double> index_us;
    std::vector<double> brute_us;
    const std::unique_ptr<pipeline::NeighborIndex> index = database.store().MakeIndex();
    if (index) index->InsertAll([&](std::size_t i) { return database.IsValid(i); });
    std::mt19937 rng(1);
    for (std::size_t q = 0; q < queries && database.size() > 0; ++q) {
        const std::size_t id = rng() % database.size();
        if (!database.IsValid(id)) continue;
        Stopwatch brute;
        std::size_t best = 0;
        double best_distance = std::numeric_limits<double>::infinity();
        for (std::size_t j = 0; j < database.size(); ++j) {
            const double d = database.Distance(id, j);
            if (d < best_distance) best_distance = d, best = j;
        }
        brute_us.push_back(1e6 * brute.Seconds());
        if (index) {
            Stopwatch indexed;
            const auto found = index->Search(*database.PrepareStored(id), 1, {});
            index_us.push_back(1e6 * indexed.Seconds());
            if (found.empty() || found.front().distance > best_distance) {
                throw core::Error("bench: index and brute force disagree (a bug; please report)");
            }
        }
        (void)best;
    }
    json["brute_force_us"] = {{"median", Quantile(brute_us, 0.5)},
                              {"p95", Quantile(brute_us, 0.95)}};
    if (index)
        json["index_us"] = {{"median", Quantile(index_us, 0.5)}, {"p95", Quantile(index_us, 0.95)}};
    return json;
}

// A database of `size` histograms made from the dataset's by small random perturbations, to
// measure how queries scale beyond the dataset's length (synthetic; said so in the output).
pipeline::DescriptorDatabase Scaled(const pipeline::DescriptorDatabase& source, std::size_t size) {
    pipeline::DescriptorDatabase scaled(source.config());
    const pipeline::CumulativeHistograms& rows = *pipeline::HistogramRows(source);
    std::mt19937 rng(2);
    std::normal_distribution<float> noise(0.0f, 0.002f);
    core::Histogram histogram;
    histogram.mass.resize(static_cast<std::size_t>(rows.bins()));
    for (std::size_t i = 0; i < size; ++i) {
        const float* base = rows.Row(i % rows.size());
        float previous = 0.0f;
        for (int k = 0; k < rows.bins(); ++k) {  // stays a valid cumulative histogram
            const float next =
                k + 1 == rows.bins()
                    ? 1.0f
                    : std::clamp(std::max(previous, base[k] + noise(rng)), 0.0f, 1.0f);
            histogram.mass[static_cast<std::size_t>(k)] = double{next} - double{previous};
            previous = next;
        }
        scaled.Add({source.method(), histogram}, static_cast<double>(i));
    }
    return scaled;
}

}  // namespace

nlohmann::json RunBench(const io::Dataset& dataset, const BenchRequest& request) {
    const io::RunConfig& config = request.config;
    config.Validate();
    // One core, so that the per-scan times are what one scan costs.
    const auto described = DescribeDataset(
        dataset, config.descriptor,
        {"describing", /*skip_bad=*/false, pipeline::Execution::kSerial, request.progress, {}});
    const auto& database = described.database;

    Stopwatch serial_clock;
    const auto matrix = pipeline::ComputeSimilarityMatrix(database, pipeline::Execution::kSerial);
    const double serial_s = serial_clock.Seconds();
    Stopwatch parallel_clock;
    pipeline::ComputeSimilarityMatrix(database, pipeline::Execution::kParallel);
    const double parallel_s = parallel_clock.Seconds();
    const double pairs = static_cast<double>(matrix.condensed().size());

    nlohmann::json json = TimingsJson(described, matrix.condensed().size(), parallel_s);
    json["method"] = core::ToString(config.descriptor.method);
    json["ns_per_comparison_one_core"] = pairs > 0 ? 1e9 * serial_s / pairs : 0.0;
    json["similarity_matrix_one_core_s"] = serial_s;
    json["queries"] = TimeQueries(database, request.queries);
    if (request.scale_to > 0 && pipeline::HistogramRows(database) != nullptr) {
        const auto scaled = Scaled(database, request.scale_to);
        json["scaled_queries"] = TimeQueries(scaled, request.queries);
        json["scaled_queries"]["stored_histograms"] = request.scale_to;
        json["scaled_queries"]["note"] = "synthetic: the dataset's histograms perturbed";
    }
    if (const auto* rows = pipeline::HistogramRows(database)) {
        json["bytes_per_stored_histogram"] =
            4 * rows->stride() + 4 * pipeline::HistogramIndex::kBlocks + 16 + 9;
    }
    json["peak_memory_mib"] = PeakMemoryMiB();
    return json;
}

}  // namespace lidarloop::app

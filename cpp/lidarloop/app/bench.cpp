#include "lidarloop/app/bench.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <limits>
#include <optional>
#include <random>

#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/app/verification_run.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/pipeline/expanded_scans.hpp"
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
            // An approximate index (scancontext's ring key) may miss the nearest scan.
            if (found.empty() || (index->IsExact() && found.front().distance > best_distance)) {
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

// Wall and thread CPU time of one step, milliseconds.
struct StepTimes {
    std::vector<double> wall_ms;
    std::vector<double> cpu_ms;

    template <typename F>
    auto Time(F&& step) {
        const Stopwatch wall;
        const ThreadCpuStopwatch cpu;
        auto result = step();
        cpu_ms.push_back(1e3 * cpu.Seconds());
        wall_ms.push_back(1e3 * wall.Seconds());
        return result;
    }
    nlohmann::json Json() const {
        return {{"wall", SummaryJson(wall_ms)}, {"thread_cpu", SummaryJson(cpu_ms)}};
    }
};

// The online step of one scan on one core, milliseconds: what a loop closer beside a SLAM front
// end spends on it (the file read excluded: a live system gets the cloud in memory).
double OnlineStepMs(const pipeline::SequenceDescriptors& described, const PreparedScans& prepared,
                    std::size_t scan, double retrieval_ms, double verification_cpu_ms) {
    return 1e3 * described.describe_seconds.at(scan) + retrieval_ms +
           1e3 * prepared.prepare_cpu_seconds.at(scan) + verification_cpu_ms;
}

// Verifies the top-k candidates of `queries` evenly spaced scans that have candidates, one pair
// at a time on this thread (in rank order up to the first accepted with
// detection.stop_at_first_loop), and sums each query's online step. `path_m`: per scan, for a gap
// in metres (empty: none known); `check`: the odometry's reach, order and gate (empty: none), as
// the online detector with a gate applies them; `retrieval_ms`: the median candidate search.
nlohmann::json TimeVerification(const pipeline::SequenceDescriptors& described,
                                const pipeline::SimilarityMatrix& matrix,
                                const PreparedScans& prepared, const io::RunConfig& config,
                                std::size_t queries, const std::vector<double>& path_m,
                                const pipeline::LoopCheck& check, double retrieval_ms) {
    std::vector<pipeline::LoopQuery> all =
        pipeline::DetectFromMatrix(matrix, described.database.times_s(), config.detection,
                                   config.descriptor.method, path_m, check);
    std::erase_if(all, [](const pipeline::LoopQuery& q) { return !q.has_match(); });
    const registration::VerificationConfig& verification = config.detection.verification;
    StepTimes coarse_times;
    StepTimes pair_times;
    std::vector<double> online_ms;
    std::size_t accepted = 0;
    const std::size_t step =
        std::max<std::size_t>(1, all.size() / std::max<std::size_t>(1, queries));
    pipeline::ExpandedScans expanded;  // as the online detector keeps its candidates
    for (std::size_t q = 0; q < all.size() && coarse_times.wall_ms.size() < queries; q += step) {
        const registration::PreparedScan query = prepared.scans[all[q].query].Expand();
        if (!query.structure) continue;
        // Every candidate's yaws (VerifyQuery leaves out those it answers without registering).
        std::vector<registration::YawWindow> windows;
        for (const pipeline::Neighbor& candidate : all[q].candidates)
            windows.push_back(check.YawWindow(all[q].query, candidate.index));
        const auto coarse = coarse_times.Time([&] {
            return std::make_optional<registration::CoarseQuery>(*query.structure,
                                                                 verification.coarse, windows);
        });
        double verification_cpu_ms = coarse_times.cpu_ms.back();
        for (const pipeline::Neighbor& candidate : all[q].candidates) {
            // The poses the odometry's gate keeps (empty: it does not judge the pair).
            const registration::PoseAllowed allowed =
                check.AllowedPoses(all[q].query, candidate.index);
            const registration::Verification verdict = pair_times.Time([&] {
                return registration::Verify(
                    query, *coarse, expanded.Get(prepared.scans, candidate.index), verification,
                    allowed, check.YawWindow(all[q].query, candidate.index));
            });
            verification_cpu_ms += pair_times.cpu_ms.back();
            const bool kept = verdict.accepted && (!allowed || allowed(verdict.T_match_query));
            accepted += kept ? 1 : 0;
            if (kept && config.detection.stop_at_first_loop) break;
        }
        online_ms.push_back(
            OnlineStepMs(described, prepared, all[q].query, retrieval_ms, verification_cpu_ms));
    }
    nlohmann::json json;
    json["queries"] = coarse_times.wall_ms.size();
    json["pairs"] = pair_times.wall_ms.size();
    json["pairs_accepted"] = accepted;
    json["top_k"] = config.detection.top_k;
    json["stop_at_first_loop"] = config.detection.stop_at_first_loop;
    json["odometry"] = static_cast<bool>(check);
    json["prepare_ms_per_scan"] = SummaryJson(prepared.prepare_seconds, 1e3);
    json["prepare_cpu_ms_per_scan"] = SummaryJson(prepared.prepare_cpu_seconds, 1e3);
    json["bytes_per_prepared_scan"] = SummaryJson(prepared.BytesPerScan());
    json["coarse_images_ms_per_query"] = coarse_times.Json();
    json["verify_ms_per_pair"] = pair_times.Json();
    json["online_step_ms_per_scan"] = SummaryJson(online_ms);
    const double median_ms = Quantile(online_ms, 0.5);
    json["online_rate_hz"] = median_ms > 0.0 ? 1e3 / median_ms : 0.0;
    return json;
}

// The median candidate search of TimeQueries' figures, milliseconds: through the index when
// the method has one, else by comparing every scan.
double RetrievalMs(const nlohmann::json& queries) {
    const nlohmann::json& figures =
        queries.contains("index_us") ? queries["index_us"] : queries["brute_force_us"];
    return figures.value("median", 0.0) / 1e3;
}

}  // namespace

nlohmann::json RunBench(const io::Dataset& dataset, const BenchRequest& request) {
    const io::RunConfig& config = request.config;
    config.Validate();
    // One core, so that the per-scan times are what one scan costs.
    const bool verify = request.verify_queries > 0 && config.detection.verify;
    PreparedScans prepared(verify ? dataset.size() : 0);
    DescribeRun run{
        "describing", /*skip_bad=*/false, pipeline::Execution::kSerial, request.progress, {}};
    if (verify) run.with_cloud = prepared.Collector(config.detection.verification.reduction);
    const auto described = DescribeDataset(dataset, config.descriptor, run);
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
    if (verify) {
        // The path on the odometry when given (as detect takes it), else on the poses.
        const std::vector<core::StampedPose> odometry =
            request.odometry_file.empty() && request.odometry_topic.empty()
                ? std::vector<core::StampedPose>{}
                : ReadOdometry(request.odometry_file, request.odometry_topic, dataset);
        const std::vector<double> path_m = core::CumulativePathM(
            odometry.empty() && dataset.HasPoses() ? dataset.poses() : odometry);
        pipeline::LoopCheck check;
        if (!odometry.empty())
            check = OdometryLoopCheck(odometry, path_m, config.posegraph, nullptr, &prepared);
        json["verification"] =
            TimeVerification(described, matrix, prepared, config, request.verify_queries, path_m,
                             check, RetrievalMs(json["queries"]));
    }
    json["peak_memory_mib"] = PeakMemoryMiB();
    return json;
}

}  // namespace lidarloop::app

#include "lidarloop/app/bench.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <string>

#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/app/verification_run.hpp"
#include "lidarloop/core/byte_codec.hpp"
#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/stopwatch.hpp"
#include "lidarloop/pipeline/expanded_scans.hpp"
#include "lidarloop/pipeline/histogram_index.hpp"
#include "lidarloop/pipeline/histogram_method.hpp"
#include "lidarloop/pipeline/neighbour_overlaps.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

namespace lidarloop::app {
namespace {

double PeakMemoryMiB() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// How many were timed, their median and 95th percentile: null when none was, rather than a 0
// that reads as measured (--queries 0).
nlohmann::json TimedJson(const std::vector<double>& values) {
    if (values.empty()) return {{"count", 0}, {"median", nullptr}, {"p95", nullptr}};
    return {{"count", values.size()},
            {"median", Quantile(values, 0.5)},
            {"p95", Quantile(values, 0.95)}};
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
    json["brute_force_us"] = TimedJson(brute_us);
    if (index) json["index_us"] = TimedJson(index_us);
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

// The first `count` scans of `database` as a database of their own (copied through the
// encoding a saved map uses).
pipeline::DescriptorDatabase FirstScans(const pipeline::DescriptorDatabase& database,
                                        std::size_t count) {
    core::ByteWriter out;
    for (std::size_t i = 0; i < count; ++i) database.Encode(i, out);
    core::ByteReader in(out.data());
    pipeline::DescriptorDatabase first(database.config());
    for (std::size_t i = 0; i < count; ++i) first.Decode(in);
    return first;
}

// The online step of one scan on one core, milliseconds: what a loop closer beside a SLAM front
// end spends on it (the file read excluded: a live system gets the cloud in memory).
double OnlineStepMs(const pipeline::SequenceDescriptors& described, const PreparedScans& prepared,
                    std::size_t scan, double candidates_ms, double verification_cpu_ms) {
    return 1e3 * described.describe_seconds.at(scan) + candidates_ms +
           1e3 * prepared.prepare_cpu_seconds.at(scan) + verification_cpu_ms;
}

// Verifies the top-k candidates of `queries` evenly spaced scans that have candidates, one pair
// at a time on this thread (in rank order up to the first accepted with
// detection.stop_at_first_loop), and sums each query's online step. `path_m`: per scan, for a gap
// in metres (empty: none known); `check`: the odometry's reach, order and gate (empty: none), as
// the online detector with a gate applies them. Each timed query's candidates are searched again
// as the online detector searches them (pipeline::StreamingDetection), timed, and verified.
nlohmann::json TimeVerification(const pipeline::SequenceDescriptors& described,
                                const PreparedScans& prepared, const io::RunConfig& config,
                                std::size_t queries, const std::vector<double>& path_m,
                                const pipeline::LoopCheck& check) {
    // The scans with candidates, among which the timed ones are spaced (memory linear in the
    // scans, as detect's own search without the matrix).
    std::vector<pipeline::LoopQuery> all = pipeline::DetectStreaming(
        described.database, config.detection, pipeline::Execution::kParallel, path_m, check);
    std::erase_if(all, [](const pipeline::LoopQuery& q) { return !q.has_match(); });
    // Each timed query verified as detect verifies it (VerifyQuery: one candidate after another,
    // those the odometry rules out answered without registering, the images of the yaws the
    // rest may take), on this thread.
    pipeline::VerificationTimes times;
    // The online step's candidate search, as the detectors make it (the index, the gap, the
    // odometry's reach, the shortlist ordered and cut), timed per query.
    const pipeline::StreamingDetection candidate_search(described.database, config.detection,
                                                        path_m, check);
    std::vector<double> candidates_ms;
    std::vector<double> online_ms;
    std::size_t accepted = 0;
    const std::size_t step =
        std::max<std::size_t>(1, all.size() / std::max<std::size_t>(1, queries));
    pipeline::ExpandedScans expanded;  // as the online detector keeps its candidates
    const auto match_of = [&](std::size_t index) { return expanded.Get(prepared.scans, index); };
    pipeline::NeighbourOverlaps neighbours(
        match_of, [&prepared] { return prepared.scans.size(); }, config.detection.verification);
    // As the online detector judges: without the motion rule (offline only).
    const pipeline::LoopCheck judge = pipeline::JudgeOf(
        check, [&neighbours](std::size_t scan) { return neighbours.Of(scan); }, {},
        config.detection.verification);
    std::size_t timed = 0;
    for (std::size_t q = 0; q < all.size() && timed < queries; q += step) {
        const registration::PreparedScan query = prepared.scans[all[q].query].Expand();
        if (!query.structure) continue;
        // The query's candidates as the online detector searches them, timed, then verified.
        const core::ThreadCpuStopwatch search_cpu;
        pipeline::LoopQuery searched = candidate_search.Detect(all[q].query);
        candidates_ms.push_back(1e3 * search_cpu.Seconds());
        pipeline::VerificationTimes query_times;
        // The whole call: the coarse images, the pairs, and without odometry the registrations
        // of the neighbours the loops are judged against.
        const core::ThreadCpuStopwatch verification_cpu;
        pipeline::VerifyQuery(searched, query, match_of, config.detection, config.descriptor.method,
                              &query_times, nullptr, pipeline::Execution::kSerial, judge);
        const double verification_cpu_ms = 1e3 * verification_cpu.Seconds();
        ++timed;
        accepted += static_cast<std::size_t>(
            std::count_if(searched.verifications.begin(), searched.verifications.end(),
                          [](const registration::Verification& v) { return v.accepted; }));
        online_ms.push_back(OnlineStepMs(described, prepared, all[q].query, candidates_ms.back(),
                                         verification_cpu_ms));
        times.Append(query_times);
    }
    const auto ms = [](const std::vector<double>& wall_s, const std::vector<double>& cpu_s) {
        return nlohmann::json{{"wall", SummaryJson(wall_s, 1e3)},
                              {"thread_cpu", SummaryJson(cpu_s, 1e3)}};
    };
    nlohmann::json json;
    json["queries"] = timed;
    json["pairs"] = times.pair_seconds.size();
    json["pairs_accepted"] = accepted;
    json["top_k"] = config.detection.top_k;
    json["stop_at_first_loop"] = config.detection.stop_at_first_loop;
    json["odometry"] = static_cast<bool>(check);
    json["prepare_ms_per_scan"] = SummaryJson(prepared.prepare_seconds, 1e3);
    json["prepare_cpu_ms_per_scan"] = SummaryJson(prepared.prepare_cpu_seconds, 1e3);
    json["bytes_per_prepared_scan"] = SummaryJson(prepared.BytesPerScan());
    json["candidates_ms_per_query"] = SummaryJson(candidates_ms);
    json["coarse_images_ms_per_query"] = ms(times.query_seconds, times.query_cpu_seconds);
    json["verify_ms_per_pair"] = ms(times.pair_seconds, times.pair_cpu_seconds);
    json["online_step_ms_per_scan"] = SummaryJson(online_ms);
    // No timed scan (none had candidates): no rate, rather than a 0 Hz that reads as measured.
    const double median_ms = Quantile(online_ms, 0.5);
    json["online_rate_hz"] =
        median_ms > 0.0 ? nlohmann::json(1e3 / median_ms) : nlohmann::json(nullptr);
    return json;
}

}  // namespace

void BenchRequest::Validate() const {
    const auto check = [](const char* name, std::size_t value, std::size_t most) {
        if (value > most) {
            throw core::ConfigError(std::string("bench: ") + name + " must be at most " +
                                    std::to_string(most) + ", got " + std::to_string(value));
        }
    };
    check("queries", queries, kMaxQueries);
    check("verify_queries", verify_queries, kMaxQueries);
    check("scale_to", scale_to, kMaxScaleTo);
    check("matrix_scans", matrix_scans, kMaxMatrixScans);
    if (matrix_scans < 2) {
        throw core::ConfigError("bench: matrix_scans must be at least 2, got " +
                                std::to_string(matrix_scans));
    }
    if (scale_to > 0 && !core::IsHistogramMethod(config.descriptor.method)) {
        throw core::ConfigError("bench: scale_to times the histogram index, and method " +
                                core::ToString(config.descriptor.method) + " has none");
    }
}

nlohmann::json RunBench(const io::Dataset& dataset, const BenchRequest& request) {
    request.Validate();
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

    // The first scans of a long sequence (4,000: 32 MB, 8 million comparisons; an hour at 10 Hz
    // whole: 2.6 GB).
    const std::size_t matrix_scans = std::min(database.size(), request.matrix_scans);
    std::optional<pipeline::DescriptorDatabase> first;
    if (matrix_scans < database.size()) first = FirstScans(database, matrix_scans);
    const pipeline::DescriptorDatabase& timed = first ? *first : database;
    Stopwatch serial_clock;
    const std::size_t matrix_pairs =
        pipeline::ComputeSimilarityMatrix(timed, pipeline::Execution::kSerial).condensed().size();
    const double serial_s = serial_clock.Seconds();
    Stopwatch parallel_clock;
    pipeline::ComputeSimilarityMatrix(timed, pipeline::Execution::kParallel);
    const double parallel_s = parallel_clock.Seconds();
    const auto pairs = static_cast<double>(matrix_pairs);

    nlohmann::json json = TimingsJson(described, matrix_pairs, parallel_s);
    json["similarity_matrix_scans"] = matrix_scans;
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
            ReadOdometryIfGiven(request.odometry_file, request.odometry_topic, dataset,
                                std::numeric_limits<double>::infinity(), request.odometry_calib);
        const std::vector<double> path_m = core::CumulativePathM(
            odometry.empty() && dataset.HasPoses() ? dataset.poses() : odometry);
        pipeline::LoopCheck check = ScansOwnCheck(prepared, config.detection.verification.coarse);
        if (!odometry.empty())
            check = OdometryLoopCheck(odometry, path_m, config.posegraph, nullptr, &prepared);
        json["verification"] =
            TimeVerification(described, prepared, config, request.verify_queries, path_m, check);
    }
    json["peak_memory_mib"] = PeakMemoryMiB();
    return json;
}

}  // namespace lidarloop::app

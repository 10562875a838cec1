// The verification figures of `lidarloop bench`: the counts recounted by registering the same
// pairs alone, the bytes per prepared scan recomputed from freshly prepared scans, the times
// positive and consistent (thread CPU time cannot exceed the wall time of the same step).
#include <algorithm>
#include <fstream>

#include <gtest/gtest.h>

#include "app_test_utils.hpp"
#include "lidarloop/app/bench.hpp"
#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/kitti_bin.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"
#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/verification.hpp"
#include "lidarloop/sim/simulator.hpp"
#include "test_utils.hpp"

namespace lidarloop {
namespace {

// 12 simulated scans (thinned VLP-16) driven twice: scan 12 + i revisits scan i exactly, so
// verification has loops to accept, in a sequence small enough for the sanitizers.
io::Dataset TinyRevisit(const std::filesystem::path& folder) {
    sim::SimulationConfig config = sim::DemoConfig();
    config.scans = 12;
    config.sensor.horizontal_steps = 360;
    const sim::Simulator simulator(config);
    std::filesystem::create_directories(folder);
    for (std::size_t i = 0; i < 2 * config.scans; ++i) {
        const std::string name = (i < 10 ? "scan0" : "scan") + std::to_string(i) + ".bin";
        io::WriteKittiBin(folder / name, simulator.Scan(i % config.scans));
    }
    return io::OpenDataset(folder);
}

// The pairs bench verifies: the candidates of `queries` evenly spaced scans that have any, as
// docs/cli.md describes --verify-queries, ordered by the scans' layouts (no odometry).
std::vector<pipeline::LoopQuery> BenchedQueries(const io::Dataset& dataset,
                                                const io::RunConfig& config, std::size_t queries) {
    const auto described = pipeline::DescribeSequence(app::SourceOf(dataset), config.descriptor);
    std::vector<registration::CompactPreparedScan> kept;
    for (std::size_t i = 0; i < dataset.size(); ++i) {
        kept.emplace_back(registration::PrepareScan(dataset.LoadScan(i),
                                                    config.detection.verification.reduction));
    }
    std::vector<pipeline::LoopQuery> all = pipeline::DetectFromMatrix(
        pipeline::ComputeSimilarityMatrix(described.database), described.database.times_s(),
        config.detection, config.descriptor.method, {},
        pipeline::LayoutOrderOf(kept, config.detection.verification.coarse));
    std::erase_if(all, [](const pipeline::LoopQuery& q) { return !q.has_match(); });
    std::vector<pipeline::LoopQuery> chosen;
    const std::size_t step = std::max<std::size_t>(1, all.size() / queries);
    for (std::size_t q = 0; q < all.size() && chosen.size() < queries; q += step) {
        chosen.push_back(all[q]);
    }
    return chosen;
}

// The median as the mean of the two middle values of an even count.
double Median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

void ExpectTimes(const nlohmann::json& step, const std::string& name) {
    for (const char* clock : {"wall", "thread_cpu"}) {
        for (const char* statistic : {"median", "p95", "max"}) {
            EXPECT_GT(step[clock][statistic].get<double>(), 0.0) << name << " " << clock;
        }
    }
    // Per sample, a thread's CPU time is at most the wall time of the same step, so each order
    // statistic is too (0.05 ms: the two clocks' resolution).
    for (const char* statistic : {"median", "p95", "max"}) {
        EXPECT_LE(step["thread_cpu"][statistic].get<double>(),
                  step["wall"][statistic].get<double>() + 0.05)
            << name << " " << statistic;
    }
}

// Counts no machine holds are refused before any work, not run until memory runs out.
TEST(BenchRun, AbsurdCountsAreRefusedBeforeAnyWork) {
    test::TempDir dir;
    const io::Dataset dataset = TinyRevisit(dir / "seq");
    const auto refused = [&](auto set) {
        app::BenchRequest request;
        set(request);
        EXPECT_THROW(app::RunBench(dataset, request), core::ConfigError);
    };
    refused([](app::BenchRequest& r) { r.scale_to = app::BenchRequest::kMaxScaleTo + 1; });
    refused([](app::BenchRequest& r) { r.queries = std::size_t(-1); });
    refused([](app::BenchRequest& r) { r.verify_queries = app::BenchRequest::kMaxQueries + 1; });
    refused([](app::BenchRequest& r) { r.matrix_scans = app::BenchRequest::kMaxMatrixScans + 1; });
    refused([](app::BenchRequest& r) { r.matrix_scans = 1; });
    refused([](app::BenchRequest& r) {  // no histogram index to scale: never silently ignored
        r.config.descriptor.method = core::Method::kNdt;
        r.scale_to = 100;
    });
    app::BenchRequest largest;
    largest.scale_to = app::BenchRequest::kMaxScaleTo;
    largest.matrix_scans = app::BenchRequest::kMaxMatrixScans;
    largest.queries = app::BenchRequest::kMaxQueries;
    EXPECT_NO_THROW(largest.Validate());
}

TEST(BenchRun, VerificationFiguresAreRecountedIndependently) {
    test::TempDir dir;
    const io::Dataset dataset = TinyRevisit(dir / "sequence");
    app::BenchRequest request;
    request.config.descriptor.method = core::Method::kRange;
    request.config.detection.min_gap.value = 10;
    request.config.detection.top_k = 2;  // registration is the slow part under the sanitizers
    request.queries = 3;
    request.verify_queries = 3;
    const nlohmann::json json = app::RunBench(dataset, request);
    ASSERT_TRUE(json.contains("verification"));
    const nlohmann::json& v = json["verification"];

    const auto queries = BenchedQueries(dataset, request.config, request.verify_queries);
    const registration::VerificationConfig& config = request.config.detection.verification;
    std::size_t pairs = 0, accepted = 0;
    ASSERT_TRUE(request.config.detection.stop_at_first_loop);  // the default
    for (const pipeline::LoopQuery& q : queries) {
        for (const pipeline::Neighbor& candidate : q.candidates) {
            ++pairs;
            const bool loop = test::VerifyAsKept(dataset.LoadScan(q.query),
                                                 dataset.LoadScan(candidate.index), config)
                                  .accepted;
            accepted += loop;
            if (loop) break;  // the online step stops at the first loop
        }
    }
    ASSERT_EQ(queries.size(), 3U);
    EXPECT_EQ(v["queries"].get<std::size_t>(), queries.size());
    EXPECT_EQ(v["pairs"].get<std::size_t>(), pairs);
    EXPECT_EQ(v["pairs_accepted"].get<std::size_t>(), accepted);
    EXPECT_GT(accepted, 0U);  // the sequence revisits: the count is not trivially zero
    EXPECT_EQ(v["top_k"].get<int>(), 2);

    std::vector<double> bytes;
    for (std::size_t i = 0; i < dataset.size(); ++i) {
        const registration::CompactPreparedScan kept(
            registration::PrepareScan(dataset.LoadScan(i), config.reduction));
        bytes.push_back(static_cast<double>(kept.MemoryBytes()));
    }
    EXPECT_DOUBLE_EQ(v["bytes_per_prepared_scan"]["median"].get<double>(), Median(bytes));
    EXPECT_EQ(v["bytes_per_prepared_scan"]["max"].get<double>(),
              *std::max_element(bytes.begin(), bytes.end()));

    for (const char* statistic : {"median", "p95", "max"}) {
        EXPECT_GT(v["prepare_ms_per_scan"][statistic].get<double>(), 0.0) << statistic;
    }
    ExpectTimes(v["coarse_images_ms_per_query"], "coarse images");
    ExpectTimes(v["verify_ms_per_pair"], "pairs");
    // Each timed query's candidates are searched and ordered, part of its online step.
    for (const char* statistic : {"median", "p95", "max"}) {
        const double candidates_ms = v["candidates_ms_per_query"][statistic].get<double>();
        EXPECT_GT(candidates_ms, 0.0) << statistic;
        EXPECT_GT(v["online_step_ms_per_scan"][statistic].get<double>(), candidates_ms)
            << statistic;
    }
}

// On a long sequence the matrix is timed on its first scans (its memory grows with the square);
// the rest of bench, the verified queries included, still covers every scan.
TEST(BenchRun, TimesTheMatrixOfTheFirstScansOnly) {
    test::TempDir dir;
    const io::Dataset dataset = TinyRevisit(dir / "sequence");
    app::BenchRequest request;
    request.config.detection.min_gap.value = 10;
    request.config.detection.top_k = 2;  // registration is the slow part under the sanitizers
    request.queries = 3;
    request.verify_queries = 3;
    const nlohmann::json whole = app::RunBench(dataset, request);
    request.matrix_scans = 5;
    const nlohmann::json first = app::RunBench(dataset, request);
    const std::size_t n = dataset.size();
    EXPECT_EQ(whole["similarity_matrix_scans"].get<std::size_t>(), n);
    EXPECT_EQ(whole["pairs"].get<std::size_t>(), n * (n - 1) / 2);
    EXPECT_EQ(first["similarity_matrix_scans"].get<std::size_t>(), 5U);
    EXPECT_EQ(first["pairs"].get<std::size_t>(), 10U);
    EXPECT_EQ(first["scans"].get<std::size_t>(), n);
    for (const char* key : {"queries", "pairs", "pairs_accepted"}) {
        EXPECT_EQ(first["verification"][key], whole["verification"][key]) << key;
    }
    EXPECT_GT(whole["verification"]["pairs"].get<std::size_t>(), 0U);
}

// A timed step with no sample (a gap longer than the sequence: no candidate pair) is no figure:
// null, not a zero that reads as a measurement.
TEST(BenchRun, WhatNothingTimedIsNull) {
    test::TempDir dir;
    const io::Dataset dataset = TinyRevisit(dir / "sequence");
    app::BenchRequest request;
    request.config.detection.min_gap.value = 1e6;
    request.queries = 3;
    request.verify_queries = 3;
    const nlohmann::json v = app::RunBench(dataset, request)["verification"];
    EXPECT_EQ(v["pairs"].get<std::size_t>(), 0U);
    for (const char* statistic : {"median", "p95", "max"}) {
        EXPECT_TRUE(v["verify_ms_per_pair"]["thread_cpu"][statistic].is_null()) << statistic;
        EXPECT_TRUE(v["online_step_ms_per_scan"][statistic].is_null()) << statistic;
        EXPECT_TRUE(v["candidates_ms_per_query"][statistic].is_null()) << statistic;
        EXPECT_GT(v["prepare_ms_per_scan"][statistic].get<double>(), 0.0) << statistic;
    }
    EXPECT_TRUE(v["online_rate_hz"].is_null());
}

// With the odometry, the timed queries shortlist, register and gate with it: here it puts each
// second-lap scan on its first-lap twin (0 m) and every other scan 50 m or more away, and drifts
// by 1 km after scan 17, so that only scans 12-17 have a candidate within reach, each its twin.
TEST(BenchRun, WithTheOdometryOnlyTheScansWithinItsReachAreTimed) {
    test::TempDir dir;
    const io::Dataset dataset = TinyRevisit(dir / "sequence");
    {
        std::ofstream odometry(dir / "odometry.txt");
        for (std::size_t i = 0; i < dataset.size(); ++i) {
            const double x_m = 50.0 * static_cast<double>(i % 12) + (i >= 18 ? 1000.0 : 0.0);
            odometry << "1 0 0 " << x_m << " 0 1 0 0 0 0 1 0\n";
        }
    }
    app::BenchRequest request;
    request.config.descriptor.method = core::Method::kRange;
    request.config.detection.min_gap.value = 10;
    request.config.detection.top_k = 2;
    request.queries = 3;
    request.verify_queries = 12;
    const nlohmann::json without = app::RunBench(dataset, request)["verification"];
    request.odometry_file = dir / "odometry.txt";
    const nlohmann::json with = app::RunBench(dataset, request)["verification"];
    EXPECT_FALSE(without["odometry"].get<bool>());
    EXPECT_EQ(without["queries"].get<std::size_t>(), 12U);
    EXPECT_TRUE(with["odometry"].get<bool>());
    EXPECT_EQ(with["queries"].get<std::size_t>(), 6U);
    EXPECT_EQ(with["pairs"].get<std::size_t>(), 6U);
    EXPECT_EQ(with["pairs_accepted"].get<std::size_t>(), 6U);
}

}  // namespace
}  // namespace lidarloop

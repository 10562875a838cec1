// The evaluation run streams the pairs (EvaluateStreamed): its figures must equal those of every
// pair in memory (EvaluateMatrix), and a run without the matrix must write the same files.
#include <algorithm>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app_test_utils.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/pipeline/scancontext_method.hpp"
#include "test_utils.hpp"

namespace lidarloop {
namespace {

void ExpectSameBest(const eval::BestThreshold& a, const eval::BestThreshold& b) {
    EXPECT_EQ(a.threshold, b.threshold);
    EXPECT_EQ(a.score, b.score);
    EXPECT_EQ(a.confusion, b.confusion);
}

void ExpectSameLearnt(const std::optional<eval::ThresholdTransfer>& a,
                      const std::optional<eval::ThresholdTransfer>& b) {
    ASSERT_EQ(a.has_value(), b.has_value());
    if (!a) return;
    EXPECT_EQ(a->threshold, b->threshold);
    EXPECT_EQ(a->train_score, b->train_score);
    EXPECT_EQ(a->train, b->train);
    EXPECT_EQ(a->test, b->test);
    EXPECT_EQ(a->test_mcc, b->test_mcc);
}

// Every figure of the evaluation, streamed (`got`) and with the pairs in memory (`want`).
void ExpectSameEvaluation(const app::MethodEvaluation& got, const app::MethodEvaluation& want) {
    SCOPED_TRACE(got.name);
    EXPECT_EQ(got.pairwise.pairs, want.pairwise.pairs);
    EXPECT_EQ(got.pairwise.positives, want.pairwise.positives);
    EXPECT_EQ(got.pairwise.distinct_thresholds, want.pairwise.distinct_thresholds);
    EXPECT_EQ(got.pairwise.roc_auc, want.pairwise.roc_auc);
    ExpectSameBest(got.pairwise.best_mcc, want.pairwise.best_mcc);
    ExpectSameBest(got.pairwise.best_f1, want.pairwise.best_f1);
    ASSERT_EQ(got.pairwise.curve.size(), want.pairwise.curve.size());
    for (std::size_t k = 0; k < got.pairwise.curve.size(); ++k) {
        EXPECT_EQ(got.pairwise.curve[k].threshold, want.pairwise.curve[k].threshold);
        EXPECT_EQ(got.pairwise.curve[k].confusion, want.pairwise.curve[k].confusion);
    }
    ExpectSameLearnt(got.learnt, want.learnt);
    EXPECT_EQ(got.learnt_on, want.learnt_on);
    EXPECT_EQ(got.at_default, want.at_default);
    EXPECT_EQ(got.at_fixed, want.at_fixed);
    ASSERT_EQ(got.best_matches.size(), want.best_matches.size());
    for (std::size_t k = 0; k < got.best_matches.size(); ++k) {
        EXPECT_EQ(got.best_matches[k].match, want.best_matches[k].match);
        EXPECT_EQ(got.best_matches[k].second_distance, want.best_matches[k].second_distance);
    }
    EXPECT_EQ(got.per_scan_at_default.has_value(), want.per_scan_at_default.has_value());
    EXPECT_EQ(got.smallest_differences, want.smallest_differences);
}

app::EvaluationRequest Request(const std::filesystem::path& out) {
    app::EvaluationRequest request;
    request.methods = {core::Method::kRange, core::Method::kNdt,
                       pipeline::ScanContextMethod::kMethod};
    request.config.detection.min_gap.value = 10;
    request.config.detection.verify = false;
    request.fixed_thresholds = {0.05, 0.1, 0.5};
    request.out = out;
    return request;
}

TEST(StreamedEvaluation, EqualsEveryPairInMemory) {
    const test::TempDir dir;
    const io::Dataset dataset = test::SmallSequence(dir / "sequence");
    for (const eval::Criterion criterion : {eval::Criterion::kMcc, eval::Criterion::kF1}) {
        app::EvaluationRequest request = Request(dir / "run");
        request.learning.criterion = criterion;
        const app::EvaluationOutcome outcome = app::RunEvaluation(dataset, request);
        for (const app::MethodEvaluation& e : outcome.methods) {
            ASSERT_EQ(e.matrix.size(), dataset.size());  // kept: small enough
            const app::MethodEvaluation want =
                app::EvaluateMatrix(e.name, e.matrix, outcome.truth, request.learning,
                                    e.default_threshold, request.fixed_thresholds);
            ExpectSameEvaluation(e, want);
            EXPECT_TRUE(e.optimum_exact);
        }
    }
}

TEST(StreamedEvaluation, ThresholdLearntOnAnotherDatasetEqualsEveryPairInMemory) {
    const test::TempDir dir;
    const io::Dataset dataset = test::SmallSequence(dir / "sequence");
    // Another town: a threshold learnt on the evaluated pairs instead would differ.
    const io::Dataset train = test::OtherSmallSequence(dir / "train", 2);
    app::EvaluationRequest request = Request(dir / "run");
    request.methods = {core::Method::kRange};
    const app::EvaluationOutcome trained = app::RunEvaluation(dataset, request, &train);
    request.out = dir / "train_run";
    const app::EvaluationOutcome on_train = app::RunEvaluation(train, request);
    const app::TrainingPairs training{
        "all pairs of " + train.root().string(),
        eval::CollectPairs(on_train.methods[0].matrix.condensed(), on_train.truth)};
    const app::MethodEvaluation& e = trained.methods[0];
    const app::MethodEvaluation want =
        app::EvaluateMatrix(e.name, e.matrix, trained.truth, request.learning, e.default_threshold,
                            request.fixed_thresholds, &training);
    ExpectSameEvaluation(e, want);
}

// Both passes over the pairs report their progress in pairs, up to all n(n-1)/2 of them.
TEST(StreamedEvaluation, TellsTheProgressOfBothPasses) {
    const test::TempDir dir;
    const io::Dataset dataset = test::SmallSequence(dir / "sequence");
    app::EvaluationRequest request = Request(dir / "run");
    request.methods = {core::Method::kRange};
    std::mutex mutex;
    std::map<std::string, std::pair<std::size_t, std::size_t>> reached;  // stage: done, total
    request.progress = [&](const std::string& stage, std::size_t done, std::size_t total) {
        const std::lock_guard<std::mutex> lock(mutex);
        auto& [most, of] = reached[stage];
        most = std::max(most, done);
        of = total;
    };
    app::RunEvaluation(dataset, request);
    const std::size_t pairs = dataset.size() * (dataset.size() - 1) / 2;
    for (const std::string pass : {"1", "2"}) {
        const std::string stage = "pairs (range), pass " + pass + " of 2";
        ASSERT_EQ(reached.count(stage), 1u) << stage;
        EXPECT_EQ(reached[stage].first, pairs) << stage;
        EXPECT_EQ(reached[stage].second, pairs) << stage;
    }
}

std::string Contents(const std::filesystem::path& file) {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// metrics.json without the timings, which differ from run to run.
nlohmann::json MetricsWithoutTimings(const std::filesystem::path& file) {
    nlohmann::json metrics = nlohmann::json::parse(Contents(file));
    for (auto& [name, method] : metrics["methods"].items()) {
        method.erase("describe_ms_per_scan_median");
        method.erase("ns_per_comparison");
    }
    return metrics;
}

TEST(StreamedEvaluation, WithoutTheMatrixTheRunWritesTheSameFiguresAndNoImages) {
    const test::TempDir dir;
    const io::Dataset dataset = test::SmallSequence(dir / "sequence");
    // A sparse results file: some pairs listed twice, most left out.
    std::ofstream(dir / "sparse.csv") << "query,match,distance\n5,40,0.5\n40,5,0.25\n100,3,1.5\n"
                                         "150,20,0.125\n20,150,0.75\n199,0,2\n60,61,0.1\n";
    app::EvaluationRequest request = Request(dir / "kept");
    request.results_files = {(dir / "sparse.csv").string()};
    const app::EvaluationOutcome kept = app::RunEvaluation(dataset, request);
    request.config.output.similarity_matrix_mib = 0;
    request.out = dir / "streamed";
    const app::EvaluationOutcome streamed = app::RunEvaluation(dataset, request);
    for (std::size_t k = 0; k < kept.methods.size(); ++k) {
        EXPECT_EQ(streamed.methods[k].matrix.size(), 0U);
        ExpectSameEvaluation(streamed.methods[k], kept.methods[k]);
    }
    EXPECT_EQ(MetricsWithoutTimings(dir / "streamed" / "metrics.json"),
              MetricsWithoutTimings(dir / "kept" / "metrics.json"));
    for (const char* file : {"roc.csv", "pr.csv"})
        EXPECT_EQ(Contents(dir / "streamed" / file), Contents(dir / "kept" / file)) << file;
    EXPECT_TRUE(std::filesystem::exists(dir / "kept" / "similarity_range.png"));
    EXPECT_FALSE(std::filesystem::exists(dir / "streamed" / "similarity_range.png"));
    EXPECT_FALSE(std::filesystem::exists(dir / "streamed" / "ground_truth.png"));
    EXPECT_NE(Contents(dir / "streamed" / "report.md").find("similarity_matrix_mib"),
              std::string::npos);
    // Its few listed pairs are all wrong: the report says the best MCC may lie elsewhere.
    EXPECT_FALSE(streamed.methods.back().optimum_exact);
    EXPECT_NE(Contents(dir / "streamed" / "report.md").find("results:sparse: the MCC is negative"),
              std::string::npos);
}

TEST(StreamedEvaluation, DistancesOfResultsEqualMatrixOfResults) {
    const test::TempDir dir;
    test::WriteFile(dir / "r.csv",
                    "query,match,distance\n3,1,0.5\n1,3,0.25\n2,2,0.1\n0,4,inf\n4,0,3\n"
                    "2,4,-1\n1,3,0.75\n");
    const pipeline::SimilarityMatrix matrix = app::MatrixOfResults(dir / "r.csv", 5);
    const eval::PairDistance distance = app::DistancesOfResults(dir / "r.csv", 5);
    for (std::size_t i = 0; i < 5; ++i) {
        for (std::size_t j = i + 1; j < 5; ++j)
            EXPECT_EQ(distance(i, j), matrix.at(i, j)) << i << ", " << j;
    }
}

}  // namespace
}  // namespace lidarloop

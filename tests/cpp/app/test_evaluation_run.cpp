// The evaluation run: a method and another detector's results file with the same distances get
// the same figures; results files and datasets without poses are checked.
#include <fstream>
#include <limits>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app_test_utils.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/read_error.hpp"
#include "test_utils.hpp"

namespace lidarloop {
namespace {

// Every pair of `matrix` as another detector's CSV (9 digits: floats read back exactly).
void WriteAllPairs(const pipeline::SimilarityMatrix& matrix, const std::filesystem::path& file) {
    std::ofstream out(file);
    out << "query,match,distance\n";
    out.precision(9);
    for (std::size_t i = 0; i < matrix.size(); ++i) {
        for (std::size_t j = i + 1; j < matrix.size(); ++j)
            out << j << ',' << i << ',' << matrix.at(i, j) << '\n';
    }
}

TEST(EvaluationRun, AResultsFileWithAMethodsDistancesScoresAsTheMethod) {
    const test::TempDir dir;
    const io::Dataset dataset = test::SmallSequence(dir / "sequence");
    app::EvaluationRequest request;
    request.methods = {core::Method::kRange};
    request.config.detection.min_gap.value = 10;
    request.config.detection.verify = false;  // the pair-wise figures only
    request.out = dir / "first";
    const app::EvaluationOutcome first = app::RunEvaluation(dataset, request);
    WriteAllPairs(first.methods.front().matrix, dir / "range.csv");

    request.results_files = {(dir / "range.csv").string()};
    request.out = dir / "second";
    const app::EvaluationOutcome second = app::RunEvaluation(dataset, request);
    ASSERT_EQ(second.methods.size(), 2U);
    const app::MethodEvaluation& method = second.methods[0];
    const app::MethodEvaluation& results = second.methods[1];
    EXPECT_EQ(results.name, "results:range");
    EXPECT_EQ(results.pairwise.best_mcc.score, method.pairwise.best_mcc.score);
    EXPECT_EQ(results.pairwise.best_f1.threshold, method.pairwise.best_f1.threshold);
    EXPECT_EQ(results.per_scan.zero_error.recall, method.per_scan.zero_error.recall);
    EXPECT_FALSE(results.default_threshold.has_value());
    ASSERT_TRUE(method.default_threshold.has_value());

    std::ifstream metrics_file(dir / "second" / "metrics.json");
    const nlohmann::json metrics = nlohmann::json::parse(metrics_file);
    EXPECT_EQ(metrics["scans"], dataset.size());
    EXPECT_EQ(metrics["methods"]["range"]["best_mcc"], method.pairwise.best_mcc.score);
    EXPECT_TRUE(metrics["methods"].contains("results:range"));
    EXPECT_TRUE(std::filesystem::exists(dir / "second" / "report.md"));
}

TEST(EvaluationRun, MatrixOfResultsKeepsTheSmallestDistanceOfAPair) {
    const test::TempDir dir;
    test::WriteFile(dir / "r.csv", "query,match,distance\n3,1,0.5\n1,3,0.25\n2,2,0.1\n");
    const pipeline::SimilarityMatrix matrix = app::MatrixOfResults(dir / "r.csv", 4);
    EXPECT_EQ(matrix.at(1, 3), 0.25f);
    EXPECT_EQ(matrix.at(0, 1), test::kInfFloat);  // never listed: never detected
    EXPECT_EQ(matrix.at(2, 3), test::kInfFloat);
}

TEST(EvaluationRun, AResultsPairBeyondTheDatasetIsAReadError) {
    const test::TempDir dir;
    test::WriteFile(dir / "r.csv", "query,match,distance\n4,1,0.5\n");
    try {
        app::MatrixOfResults(dir / "r.csv", 4);
        FAIL() << "no error";
    } catch (const io::ReadError& e) {
        EXPECT_NE(std::string(e.what()).find("r.csv: line 2: pair (4, 1) names a scan beyond "
                                             "the 4 of the dataset"),
                  std::string::npos)
            << e.what();
    }
}

// A NaN threshold to report MCC and F1 at decides nothing and is refused (a negative one fits a
// results file of negated similarities); so is a request with nothing to evaluate.
TEST(EvaluationRun, NoMethodOrANanFixedThresholdIsAConfigError) {
    const test::TempDir dir;
    const io::Dataset dataset = test::SmallSequence(dir / "sequence");
    app::EvaluationRequest request;
    request.methods = {core::Method::kHeight};
    request.out = dir / "out";
    request.fixed_thresholds = {0.01, std::numeric_limits<double>::quiet_NaN()};
    EXPECT_THROW(app::RunEvaluation(dataset, request), core::ConfigError);
    request.fixed_thresholds.clear();
    request.methods.clear();  // nothing to evaluate is no empty report
    EXPECT_THROW(app::RunEvaluation(dataset, request), core::ConfigError);
    EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(EvaluationRun, ADatasetWithoutPosesIsAClearError) {
    const test::TempDir dir;
    test::SmallSequence(dir / "sequence");
    std::filesystem::create_directories(dir / "bare" / "velodyne");
    std::filesystem::copy(dir / "sequence" / "velodyne", dir / "bare" / "velodyne");
    app::EvaluationRequest request;
    request.methods = {core::Method::kHeight};
    request.out = dir / "out";
    EXPECT_THROW(app::RunEvaluation(io::OpenDataset(dir / "bare"), request), core::ConfigError);
    EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

}  // namespace
}  // namespace lidarloop

// Scan Context as a registered method, end to end: detection with verification, a saved map,
// evaluation beside the papers' methods, the ring-key search and the describe JSON.
#include <algorithm>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app_test_utils.hpp"
#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/app/descriptor_json.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/pipeline/scancontext_method.hpp"
#include "lidarloop/pipeline/sequence.hpp"
#include "test_utils.hpp"

namespace lidarloop {
namespace {

class ScanContextRuns : public ::testing::Test {
protected:
    void SetUp() override { dataset_.emplace(test::SmallSequence(dir_ / "sequence")); }
    app::DetectRequest Request(const std::string& out) const {
        app::DetectRequest request;
        io::ApplyConfigYaml("method: scancontext\ndetection:\n  min_gap: 10\n  top_k: 2\n",
                            "sc.yaml", request.config);
        request.out = dir_ / out;
        return request;
    }

    test::TempDir dir_;
    std::optional<io::Dataset> dataset_;
};

TEST_F(ScanContextRuns, DetectionVerifiesItsCandidatesLikeAnyMethods) {
    // Verification does not depend on the method; it runs under the sanitizers in DetectionRun.
    LIDARLOOP_RELEASE_SUITE_ONLY();
    const app::DetectRequest request = Request("verified");
    ASSERT_TRUE(request.config.detection.verify);
    const app::DetectOutcome outcome = app::RunDetect(*dataset_, request);
    EXPECT_EQ(outcome.threshold, 0.13);
    std::size_t verified = 0;
    for (const pipeline::LoopQuery& q : outcome.queries) {
        ASSERT_EQ(q.verifications.size(), q.candidates.size()) << q.query;
        verified += q.candidates.size();
    }
    EXPECT_GT(verified, 300U);
    EXPECT_GT(outcome.accepted, 0U);  // the demo town revisits its streets
    EXPECT_TRUE(std::filesystem::exists(request.out / "database.lldb"));
}

TEST_F(ScanContextRuns, ASavedMapLocalisesEveryScanAtItself) {
    app::DetectRequest request = Request("detect");
    request.config.detection.verify = false;
    request.config.detection.top_k = 1;
    app::RunDetect(*dataset_, request);
    request.out = dir_ / "localise";
    const app::DetectOutcome outcome =
        app::RunLocalise(*dataset_, app::LoadMap(dir_ / "detect" / "database.lldb"), request);
    ASSERT_EQ(outcome.queries.size(), dataset_->size());
    for (const pipeline::LoopQuery& q : outcome.queries) {
        ASSERT_TRUE(q.has_match()) << q.query;
        EXPECT_EQ(q.candidates.front().distance, 0.0) << q.query;
        EXPECT_TRUE(q.accepted) << q.query;
    }
}

TEST_F(ScanContextRuns, IsEvaluatedBesideRange) {
    app::EvaluationRequest request;
    request.config = Request("unused").config;
    request.config.detection.verify = false;
    request.methods = {pipeline::ScanContextMethod::kMethod, core::Method::kRange};
    request.out = dir_ / "evaluation";
    const app::EvaluationOutcome outcome = app::RunEvaluation(*dataset_, request);
    ASSERT_EQ(outcome.methods.size(), 2U);
    EXPECT_EQ(outcome.methods[0].name, "scancontext");
    EXPECT_EQ(outcome.methods[0].default_threshold, 0.13);
    EXPECT_EQ(outcome.methods[0].pairwise.pairs, outcome.methods[1].pairwise.pairs);
    std::ifstream metrics_file(request.out / "metrics.json");
    EXPECT_TRUE(nlohmann::json::parse(metrics_file)["methods"].contains("scancontext"));
}

// With at least as many ring-key candidates as scans the two-stage search is the exhaustive
// one; with few it returns a subset of scans ranked by the full distance. (Offline detection that
// keeps the similarity matrix ranks from the matrix, which compares every pair.)
TEST_F(ScanContextRuns, TheRingKeySearchRanksItsCandidatesByTheFullDistance) {
    app::DetectRequest exact = Request("exact");
    exact.config.detection.verify = false;
    exact.config.detection.top_k = 5;
    // Without the similarity matrix, detect searches through the method's index.
    exact.config.output.similarity_matrix_mib = 0;
    app::DetectRequest all = exact;
    all.out = dir_ / "all";
    all.config.descriptor.methods.Mutable<core::ScanContextConfig>("scancontext")
        .ring_key_candidates = 1000;
    app::DetectRequest few = exact;
    few.out = dir_ / "few";
    few.config.descriptor.methods.Mutable<core::ScanContextConfig>("scancontext")
        .ring_key_candidates = 8;
    const app::DetectOutcome a = app::RunDetect(*dataset_, exact);
    const app::DetectOutcome b = app::RunDetect(*dataset_, all);
    const app::DetectOutcome c = app::RunDetect(*dataset_, few);
    const auto described =
        pipeline::DescribeSequence(app::SourceOf(*dataset_), exact.config.descriptor);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.queries.size(); ++i) {
        const auto& exact_candidates = a.queries[i].candidates;
        ASSERT_EQ(b.queries[i].candidates.size(), exact_candidates.size()) << i;
        for (std::size_t r = 0; r < exact_candidates.size(); ++r)
            EXPECT_EQ(b.queries[i].candidates[r].index, exact_candidates[r].index) << i;
        const auto& found = c.queries[i].candidates;
        ASSERT_EQ(found.size(), exact_candidates.size()) << i;
        for (std::size_t r = 0; r < found.size(); ++r) {
            EXPECT_NEAR(found[r].distance, described.database.Distance(found[r].index, i), 1e-6);
            if (r > 0) {
                EXPECT_LE(found[r - 1].distance, found[r].distance) << i;
            }
            // Never better than the exhaustive search at the same rank.
            EXPECT_GE(found[r].distance, exact_candidates[r].distance - 1e-6) << i;
        }
        differ += !found.empty() && found[0].index != exact_candidates[0].index ? 1 : 0;
    }
    EXPECT_LT(differ, a.queries.size());
}

TEST_F(ScanContextRuns, DescribeShowsTheMatrixAndTheRingKey) {
    core::DescriptorConfig config;
    config.method = pipeline::ScanContextMethod::kMethod;
    const core::Descriptor d = pipeline::ComputeDescriptor(dataset_->LoadScan(0), config);
    const nlohmann::json json = app::DescriptorJson(d);
    EXPECT_EQ(json["method"], "scancontext");
    ASSERT_EQ(json["bins"].size(), 20U);
    EXPECT_EQ(json["bins"][0].size(), 60U);
    EXPECT_EQ(json["ring_key"].size(), 20U);
    EXPECT_GT(json["points_used"].get<std::size_t>(), 1000U);
}

}  // namespace
}  // namespace lidarloop

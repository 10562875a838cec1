// End to end on the demo sequence through the run layer, as `lidarloop evaluate --train-on` runs
// it: simulate two worlds, learn each method's threshold on all pairs of one and test it on the
// other, so nothing is tuned to the test data.
#include <gtest/gtest.h>

#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/app/simulation.hpp"
#include "lidarloop/eval/metrics.hpp"
#include "test_utils.hpp"

namespace lidarloop {
namespace {

io::Dataset SimulateDemo(std::uint64_t seed, const std::filesystem::path& folder) {
    sim::SimulationConfig config = sim::DemoConfig();
    config.seed = seed;
    app::WriteSimulation(sim::Simulator(config), folder, /*run=*/{}, /*threads=*/0);
    return io::OpenDataset(folder);
}

void ExpectLoopsFoundWellAboveChance(const app::MethodEvaluation& e) {
    ASSERT_TRUE(e.learnt.has_value()) << e.name;
    const eval::Confusion& c = e.learnt->test;
    const double recall = eval::Recall(c);
    const double fpr = eval::FalsePositiveRate(c);
    // A detector that guesses finds loops at the rate it raises false alarms (TPR = FPR).
    EXPECT_GT(recall, 5.0 * fpr) << e.name << ": recall " << recall << ", FPR " << fpr << " at tau "
                                 << e.learnt->threshold;
    EXPECT_GT(c.tp, 20U) << e.name;
    EXPECT_GT(eval::Mcc(c), 0.05) << e.name;
}

TEST(DemoSequence, LoopsFoundAtAThresholdLearntOnAnotherSeed) {
    // Two demo-length sequences; a threshold learnt on another dataset runs under the sanitizers
    // in StreamedEvaluation.ThresholdLearntOnAnotherDatasetEqualsEveryPairInMemory.
    LIDARLOOP_RELEASE_SUITE_ONLY();
    const test::TempDir dir;
    const io::Dataset train = SimulateDemo(2, dir / "seed2");
    const io::Dataset test = SimulateDemo(1, dir / "seed1");
    app::EvaluationRequest request;
    request.methods = {core::Method::kHeight, core::Method::kNdt};
    request.config.detection.verify = false;  // learnt thresholds of the descriptors
    request.out = dir / "evaluation";  // Röhling's rule: same place within 10 m, gap 30 scans
    const app::EvaluationOutcome outcome = app::RunEvaluation(test, request, &train);
    ASSERT_EQ(outcome.methods.size(), 2U);
    for (const app::MethodEvaluation& e : outcome.methods) {
        ExpectLoopsFoundWellAboveChance(e);
        EXPECT_EQ(e.learnt_on, "all pairs of " + (dir / "seed2").string());
    }
    EXPECT_TRUE(std::filesystem::exists(dir / "evaluation" / "metrics.json"));
    EXPECT_TRUE(std::filesystem::exists(dir / "evaluation" / "report.md"));
}

}  // namespace
}  // namespace lidarloop

// End to end on the demo sequence: simulate, describe, compare, evaluate. The threshold is
// chosen on one seed's world and applied to another's, so nothing is tuned to the test data.
#include <gtest/gtest.h>

#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/eval/ground_truth.hpp"
#include "lidarloop/eval/metrics.hpp"
#include "lidarloop/eval/pairwise.hpp"
#include "lidarloop/pipeline/sequence.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"
#include "lidarloop/sim/simulator.hpp"

namespace lidarloop {
namespace {

struct ScoredSequence {
    std::vector<eval::ScoredPair> pairs;
};

ScoredSequence ScoreDemo(std::uint64_t seed, core::Method method) {
    sim::SimulationConfig config = sim::DemoConfig();
    config.seed = seed;
    const sim::Simulator simulator(config);
    pipeline::ScanSource source;
    source.count = simulator.size();
    source.load = [&](std::size_t i) { return simulator.Scan(i); };
    source.time_s = [&](std::size_t i) { return simulator.GroundTruthPose(i).time_s; };
    core::DescriptorConfig descriptor;
    descriptor.method = method;
    const auto described = pipeline::DescribeSequence(source, descriptor);
    const auto matrix = pipeline::ComputeSimilarityMatrix(described.database);
    std::vector<core::StampedPose> poses;
    for (std::size_t i = 0; i < simulator.size(); ++i)
        poses.push_back(simulator.GroundTruthPose(i));
    eval::GroundTruthConfig rule;  // Röhling: same place within 10 m
    rule.min_gap = {30.0, core::MinGap::Unit::kScans};
    const eval::GroundTruth truth = eval::BuildGroundTruth(poses, rule);
    return {eval::CollectPairs(matrix.condensed(), truth)};
}

void ExpectLoopsFoundWellAboveChance(core::Method method) {
    const ScoredSequence train = ScoreDemo(2, method);
    const double tau = eval::EvaluatePairs(train.pairs).best_mcc.threshold;
    const ScoredSequence test = ScoreDemo(1, method);
    const eval::Confusion c = eval::ConfusionAt(test.pairs, tau);
    const double recall = eval::Recall(c);
    const double fpr = eval::FalsePositiveRate(c);
    // A detector that guesses finds loops at the rate it raises false alarms (TPR = FPR).
    EXPECT_GT(recall, 5.0 * fpr) << core::ToString(method) << ": recall " << recall << ", FPR "
                                 << fpr << " at tau " << tau;
    EXPECT_GT(c.tp, 20U) << core::ToString(method);
    EXPECT_GT(eval::Mcc(c), 0.05) << core::ToString(method);
}

TEST(DemoSequence, HistogramsFindLoopsAtAThresholdChosenOnAnotherSeed) {
    ExpectLoopsFoundWellAboveChance(core::Method::kHeight);
}

TEST(DemoSequence, NdtFindsLoopsAtAThresholdChosenOnAnotherSeed) {
    ExpectLoopsFoundWellAboveChance(core::Method::kNdt);
}

}  // namespace
}  // namespace lidarloop

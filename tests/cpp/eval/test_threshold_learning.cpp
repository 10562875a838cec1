#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/threshold_learning.hpp"
#include "test_utils.hpp"

namespace lidarloop::eval {
namespace {

// Scans 0..19; loops have distance 0.1 + 0.01 j in the first half and 0.3 in the second (the
// detector drifts), non-loops 0.5 + 0.01 j.
std::vector<ScoredPair> DriftingPairs() {
    std::vector<ScoredPair> pairs;
    for (std::uint32_t j = 1; j < 20; ++j) {
        for (std::uint32_t i = 0; i < j; ++i) {
            const bool loop = (i + j) % 4 == 0;
            const auto step = 0.01f * static_cast<float>(j);
            const float base = loop ? (j < 10 ? 0.1f + step : 0.3f) : 0.5f + step;
            pairs.push_back({i, j, base, loop});
        }
    }
    return pairs;
}

TEST(ThresholdLearning, SplitByQueryPartitionsThePairs) {
    const auto pairs = DriftingPairs();
    const PairSplit split = SplitByQuery(pairs, 10);
    EXPECT_EQ(split.first_test_scan, 10u);
    EXPECT_EQ(split.train.size() + split.test.size(), pairs.size());
    EXPECT_EQ(split.train.size(), 45u);  // pairs with j < 10
    for (const auto& p : split.train) EXPECT_LT(p.j, 10u);
    for (const auto& p : split.test) EXPECT_GE(p.j, 10u);
}

TEST(ThresholdLearning, LearnAndTestGivesATableIRow) {
    const auto pairs = DriftingPairs();
    const PairSplit split = SplitByQuery(pairs, 10);
    const ThresholdTransfer row = LearnAndTest(split.train, split.test, Criterion::kMcc);
    // Training loops end at 0.1 + 0.01 * 9 (scan 9's loops), non-loops start at 0.51.
    EXPECT_EQ(row.threshold, static_cast<double>(0.1f + 0.01f * 9));
    EXPECT_DOUBLE_EQ(row.train_score, 1.0);
    EXPECT_EQ(row.train.fp, 0u);
    EXPECT_EQ(row.train.fn, 0u);
    // On the test part every loop sits at 0.3 > tau: nothing is detected.
    EXPECT_EQ(row.test.tp, 0u);
    EXPECT_EQ(row.test.fp, 0u);
    EXPECT_EQ(row.test, ConfusionAt(split.test, row.threshold));
    EXPECT_DOUBLE_EQ(row.test_f1, 0.0);
    EXPECT_DOUBLE_EQ(row.test_mcc, 0.0);
    // Learning on the test part itself recovers a perfect threshold there.
    const ThresholdTransfer self = LearnAndTest(split.test, split.test, Criterion::kF1);
    EXPECT_DOUBLE_EQ(self.test_f1, 1.0);
    EXPECT_EQ(self.threshold, static_cast<double>(0.3f));
}

TEST(ThresholdLearning, LearnOnFirstPart) {
    const auto pairs = DriftingPairs();
    ThresholdLearningConfig config;
    config.train_fraction = 0.5;
    const ThresholdTransfer row = LearnOnFirstPart(pairs, 20, config);
    const PairSplit split = SplitByQuery(pairs, 10);
    const ThresholdTransfer expected = LearnAndTest(split.train, split.test, Criterion::kMcc);
    EXPECT_EQ(row.threshold, expected.threshold);
    EXPECT_EQ(row.test, expected.test);
    config.train_fraction = 0.01;  // round(0.2) = 0: no training pair
    EXPECT_THROW(LearnOnFirstPart(pairs, 20, config), core::EmptyInputError);
    EXPECT_THROW(LearnAndTest(pairs, {}, Criterion::kMcc), core::EmptyInputError);
}

// A detector that lists one training loop and omits the other and both non-loops, as a top-1
// results file does. At +inf (everything a loop) training MCC would be 0 and F1 2/3; an omitted
// pair is never detected, so the learnt tau is the listed distance, finite.
TEST(ThresholdLearning, OmittedPairsNeverMakeTheLearntThresholdInfinite) {
    constexpr float kOmitted = std::numeric_limits<float>::infinity();
    const std::vector<ScoredPair> train{
        {0, 3, 0.4f, false}, {1, 3, kOmitted, true}, {0, 4, kOmitted, true}, {2, 4, 0.2f, false}};
    const std::vector<ScoredPair> test{{0, 5, 0.3f, true}, {1, 5, kOmitted, false}};
    for (const Criterion criterion : {Criterion::kMcc, Criterion::kF1}) {
        const ThresholdTransfer row = LearnAndTest(train, test, criterion);
        // At 0.2: TP 0, FP 1, TN 1, FN 2: MCC -2 / sqrt(1 * 2 * 2 * 3), F1 0; at 0.4 MCC -1.
        EXPECT_EQ(row.threshold, static_cast<double>(0.2f)) << ToString(criterion);
        EXPECT_EQ(row.train, (Confusion{0, 1, 1, 2}));
        EXPECT_EQ(row.test, (Confusion{0, 0, 1, 1}));  // the loop at 0.3 > tau is missed
    }
}

TEST(ThresholdLearning, NoFiniteTrainingDistanceLearnsNothing) {
    constexpr float kOmitted = std::numeric_limits<float>::infinity();
    const std::vector<ScoredPair> train{{0, 3, kOmitted, true}, {1, 3, kOmitted, false}};
    const std::vector<ScoredPair> test{{0, 5, 0.3f, true}};
    EXPECT_THROW(LearnAndTest(train, test, Criterion::kF1), core::EmptyInputError);
}

TEST(ThresholdLearning, RejectsAbsurdConfigs) {
    for (const double fraction : {0.0, 1.0, -0.5, 2.0, std::numeric_limits<double>::quiet_NaN()}) {
        ThresholdLearningConfig config;
        config.train_fraction = fraction;
        EXPECT_TRUE(test::Contains(test::ConfigErrorOf([&] { config.Validate(); }),
                                   "threshold_learning.train_fraction"))
            << fraction;
    }
    EXPECT_EQ(ParseCriterion("mcc"), Criterion::kMcc);
    EXPECT_EQ(ParseCriterion(ToString(Criterion::kF1)), Criterion::kF1);
    EXPECT_THROW(ParseCriterion("auc"), core::ConfigError);
    EXPECT_EQ(test::ConfigErrorOf([] { ParseCriterion("auc"); }),
              "unknown threshold criterion 'auc' (valid: mcc, f1)");
}

}  // namespace
}  // namespace lidarloop::eval

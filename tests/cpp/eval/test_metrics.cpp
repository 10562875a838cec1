#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "lidarloop/eval/metrics.hpp"

namespace lidarloop::eval {
namespace {

TEST(Metrics, HandComputedConfusion) {
    const Confusion c{6, 2, 10, 4};
    EXPECT_DOUBLE_EQ(Precision(c), 0.75);
    EXPECT_DOUBLE_EQ(Recall(c), 0.6);
    EXPECT_DOUBLE_EQ(FalsePositiveRate(c), 2.0 / 12.0);
    EXPECT_DOUBLE_EQ(F1(c), 12.0 / 18.0);
    // (6*10 - 2*4) / sqrt(8 * 10 * 12 * 14)
    EXPECT_NEAR(Mcc(c), 52.0 / std::sqrt(13440.0), 1e-15);
    EXPECT_EQ(c.Positives(), 10u);
    EXPECT_EQ(c.Negatives(), 12u);
    EXPECT_EQ(c.PredictedPositives(), 8u);
    EXPECT_EQ(c.Total(), 22u);
}

TEST(Metrics, PerfectAndInvertedDetectors) {
    const Confusion perfect{7, 0, 13, 0};
    EXPECT_DOUBLE_EQ(Precision(perfect), 1.0);
    EXPECT_DOUBLE_EQ(Recall(perfect), 1.0);
    EXPECT_DOUBLE_EQ(F1(perfect), 1.0);
    EXPECT_DOUBLE_EQ(Mcc(perfect), 1.0);
    const Confusion inverted{0, 5, 0, 5};
    EXPECT_DOUBLE_EQ(Mcc(inverted), -1.0);
    EXPECT_DOUBLE_EQ(F1(inverted), 0.0);
    EXPECT_DOUBLE_EQ(FalsePositiveRate(inverted), 1.0);
}

TEST(Metrics, NoPositivesInTruth) {
    const Confusion some_detected{0, 3, 7, 0};
    EXPECT_DOUBLE_EQ(Recall(some_detected), 0.0);  // 0 / 0 -> 0
    EXPECT_DOUBLE_EQ(Precision(some_detected), 0.0);
    EXPECT_DOUBLE_EQ(F1(some_detected), 0.0);
    EXPECT_DOUBLE_EQ(Mcc(some_detected), 0.0);  // TP + FN = 0
    EXPECT_DOUBLE_EQ(FalsePositiveRate(some_detected), 0.3);
    const Confusion only_true_negatives{0, 0, 9, 0};
    EXPECT_DOUBLE_EQ(Precision(only_true_negatives), 0.0);
    EXPECT_DOUBLE_EQ(Recall(only_true_negatives), 0.0);
    EXPECT_DOUBLE_EQ(F1(only_true_negatives), 0.0);  // 2TP + FP + FN = 0
    EXPECT_DOUBLE_EQ(Mcc(only_true_negatives), 0.0);
    EXPECT_DOUBLE_EQ(FalsePositiveRate(only_true_negatives), 0.0);
}

TEST(Metrics, AllPositivesInTruth) {
    const Confusion c{8, 0, 0, 2};
    EXPECT_DOUBLE_EQ(Precision(c), 1.0);
    EXPECT_DOUBLE_EQ(Recall(c), 0.8);
    EXPECT_DOUBLE_EQ(F1(c), 16.0 / 18.0);
    EXPECT_DOUBLE_EQ(FalsePositiveRate(c), 0.0);  // no negatives: 0 / 0 -> 0
    EXPECT_DOUBLE_EQ(Mcc(c), 0.0);                // TN + FP = 0
}

TEST(Metrics, MccDenominatorZeroWhenNothingOrEverythingDetected) {
    EXPECT_DOUBLE_EQ(Mcc(Confusion{0, 0, 5, 5}), 0.0);  // nothing detected
    EXPECT_DOUBLE_EQ(Precision(Confusion{0, 0, 5, 5}), 0.0);
    EXPECT_DOUBLE_EQ(F1(Confusion{0, 0, 5, 5}), 0.0);
    EXPECT_DOUBLE_EQ(Mcc(Confusion{5, 5, 0, 0}), 0.0);  // everything detected
    EXPECT_DOUBLE_EQ(F1(Confusion{5, 5, 0, 0}), 10.0 / 15.0);
    const Confusion empty{};
    EXPECT_DOUBLE_EQ(Precision(empty), 0.0);
    EXPECT_DOUBLE_EQ(Recall(empty), 0.0);
    EXPECT_DOUBLE_EQ(FalsePositiveRate(empty), 0.0);
    EXPECT_DOUBLE_EQ(F1(empty), 0.0);
    EXPECT_DOUBLE_EQ(Mcc(empty), 0.0);
}

TEST(Metrics, LargeCountsDoNotOverflow) {
    const Confusion c{4'000'000'000ull, 1'000'000'000ull, 90'000'000'000ull, 2'000'000'000ull};
    const long double tp = 4e9L, fp = 1e9L, tn = 9e10L, fn = 2e9L;
    const long double expected =
        (tp * tn - fp * fn) / std::sqrt((tp + fp) * (tp + fn) * (tn + fp) * (tn + fn));
    EXPECT_NEAR(Mcc(c), static_cast<double>(expected), 1e-12);
}

TEST(Metrics, BoundsAndClassSymmetryOnRandomConfusions) {
    std::mt19937 rng(17);
    std::uniform_int_distribution<std::uint64_t> count(0, 50);
    for (int k = 0; k < 2000; ++k) {
        const Confusion c{count(rng), count(rng), count(rng), count(rng)};
        for (const double rate : {Precision(c), Recall(c), FalsePositiveRate(c), F1(c)}) {
            EXPECT_GE(rate, 0.0);
            EXPECT_LE(rate, 1.0);
        }
        EXPECT_GE(Mcc(c), -1.0);
        EXPECT_LE(Mcc(c), 1.0);
        // Swapping the roles of the classes leaves MCC unchanged.
        EXPECT_NEAR(Mcc(c), Mcc(Confusion{c.tn, c.fn, c.tp, c.fp}), 1e-12);
        // F1 is the harmonic mean of precision and recall when both are defined.
        if (c.tp > 0) {
            const double p = Precision(c);
            const double r = Recall(c);
            EXPECT_NEAR(F1(c), 2 * p * r / (p + r), 1e-12);
        }
    }
}

}  // namespace
}  // namespace lidarloop::eval

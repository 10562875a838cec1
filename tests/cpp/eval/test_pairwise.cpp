#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "eval/eval_test_utils.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/pairwise.hpp"
#include "test_utils.hpp"

namespace lidarloop::eval {
namespace {

using test::kInf;

// `count` pairs, loops with probability `loop_rate`; distances quantised to `levels` values so
// that ties occur; loops are shifted down by `separation` (0 = an uninformative detector).
std::vector<ScoredPair> RandomPairs(unsigned seed, std::size_t count, double loop_rate, int levels,
                                    double separation) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<ScoredPair> pairs(count);
    for (std::size_t k = 0; k < count; ++k) {
        pairs[k].i = static_cast<std::uint32_t>(k % 97);
        pairs[k].j = static_cast<std::uint32_t>(97 + k);
        pairs[k].loop = unit(rng) < loop_rate;
        double d = unit(rng) - (pairs[k].loop ? separation : 0.0);
        if (levels > 0) d = std::round(d * levels) / levels;
        pairs[k].distance = static_cast<float>(d);
    }
    return pairs;
}

// Reference optimum: every distinct finite distance tried with ConfusionAt, ties to the
// smallest tau (+inf marks an unscored pair, which no threshold may detect).
BestThreshold BruteBest(const std::vector<ScoredPair>& pairs, double (*metric)(const Confusion&)) {
    std::set<float> distinct;
    for (const auto& p : pairs) {
        if (std::isfinite(p.distance)) distinct.insert(p.distance);
    }
    BestThreshold best;
    bool have = false;
    for (const float tau : distinct) {
        const Confusion c = ConfusionAt(pairs, tau);
        if (!have || metric(c) > best.score) best = {tau, metric(c), c};
        have = true;
    }
    return best;
}

TEST(Pairwise, CondensedLayoutIsRowMajorUpperTriangle) {
    const std::size_t n = 9;
    std::size_t at = 0;
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n; ++j) EXPECT_EQ(CondensedIndex(n, i, j), at++);
    }
    EXPECT_EQ(CondensedSize(n), at);
    EXPECT_EQ(CondensedSize(0), 0u);
    EXPECT_EQ(CondensedSize(1), 0u);
}

TEST(Pairwise, CollectPairsSkipsTheGapAndLabelsLoops) {
    std::vector<core::StampedPose> poses;
    for (int i = 0; i < 8; ++i) poses.push_back(test::MakePose(i, 3.0 * i, 0.0));
    poses[7] = test::MakePose(7, 0.5, 0.0);  // back at scan 0
    GroundTruthConfig config;
    config.distance_m = 2.0;
    config.min_gap = {2.0, core::MinGap::Unit::kScans};
    const GroundTruth truth = BuildGroundTruth(poses, config);
    std::vector<float> condensed(CondensedSize(8));
    for (std::size_t k = 0; k < condensed.size(); ++k) condensed[k] = static_cast<float>(k);
    const auto pairs = CollectPairs(condensed, truth);
    EXPECT_EQ(pairs.size(), truth.ComparablePairCount());
    EXPECT_EQ(pairs.size(), 15u);  // |i - j| >= 3 among 8 scans: 5 + 4 + 3 + 2 + 1
    std::size_t loops = 0;
    for (const auto& p : pairs) {
        EXPECT_GT(p.j - p.i, 2u);
        EXPECT_EQ(p.distance, static_cast<float>(CondensedIndex(8, p.i, p.j)));
        EXPECT_EQ(p.loop, p.i == 0 && p.j == 7);
        loops += p.loop ? 1 : 0;
    }
    EXPECT_EQ(loops, 1u);
    condensed[CondensedIndex(8, 6, 7)] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_NO_THROW(CollectPairs(condensed, truth));  // inside the gap: never read
    condensed[CondensedIndex(8, 0, 7)] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(CollectPairs(condensed, truth), core::Error);
    condensed.pop_back();
    EXPECT_THROW(CollectPairs(condensed, truth), core::Error);
}

TEST(Pairwise, PerfectDetectorHasAucOneAndMccOne) {
    std::vector<ScoredPair> pairs;
    for (std::uint32_t k = 0; k < 200; ++k) {
        const bool loop = k % 5 == 0;
        pairs.push_back({k, k + 1000,
                         (loop ? 0.001f : 1.0f) * static_cast<float>(k) + (loop ? 0.0f : 1.0f),
                         loop});
    }
    const PairwiseEvaluation result = EvaluatePairs(pairs);
    ASSERT_TRUE(result.roc_auc.has_value());
    EXPECT_DOUBLE_EQ(*result.roc_auc, 1.0);
    EXPECT_DOUBLE_EQ(result.best_mcc.score, 1.0);
    EXPECT_DOUBLE_EQ(result.best_f1.score, 1.0);
    EXPECT_FLOAT_EQ(static_cast<float>(result.best_mcc.threshold), 0.001f * 195.0f);
    EXPECT_EQ(result.best_mcc.confusion, (Confusion{40, 0, 160, 0}));
    EXPECT_EQ(result.positives, 40u);
    EXPECT_EQ(result.negatives, 160u);
}

TEST(Pairwise, RandomDetectorHasAucNearHalf) {
    const auto pairs = RandomPairs(21, 20000, 0.2, 0, 0.0);
    const PairwiseEvaluation result = EvaluatePairs(pairs);
    const auto n1 = static_cast<double>(result.positives);
    const auto n0 = static_cast<double>(result.negatives);
    // Standard deviation of the AUC of an uninformative score (Mann-Whitney).
    const double sigma = std::sqrt((n0 + n1 + 1.0) / (12.0 * n0 * n1));
    ASSERT_TRUE(result.roc_auc.has_value());
    EXPECT_NEAR(*result.roc_auc, 0.5, 4.0 * sigma);
}

TEST(Pairwise, AucEqualsMannWhitneyWithTies) {
    const auto pairs = RandomPairs(8, 600, 0.3, 12, 0.2);
    double wins = 0.0;
    double comparisons = 0.0;
    for (const auto& loop : pairs) {
        if (!loop.loop) continue;
        for (const auto& other : pairs) {
            if (other.loop) continue;
            comparisons += 1.0;
            wins += loop.distance < other.distance    ? 1.0
                    : loop.distance == other.distance ? 0.5
                                                      : 0.0;
        }
    }
    const PairwiseEvaluation result = EvaluatePairs(pairs);
    EXPECT_NEAR(*result.roc_auc, wins / comparisons, 1e-12);
}

TEST(Pairwise, RocCurveIsMonotoneAndThinned) {
    const auto pairs = RandomPairs(3, 50000, 0.1, 0, 0.3);
    PairwiseConfig config;
    config.max_curve_points = 100;
    const PairwiseEvaluation thin = EvaluatePairs(pairs, config);
    config.max_curve_points = 0;
    const PairwiseEvaluation full = EvaluatePairs(pairs, config);
    EXPECT_EQ(full.curve.size(), full.distinct_thresholds + 1);
    EXPECT_LE(thin.curve.size(), 100u);
    EXPECT_GE(thin.curve.size(), 50u);
    EXPECT_EQ(*thin.roc_auc, *full.roc_auc);
    EXPECT_EQ(thin.best_mcc.threshold, full.best_mcc.threshold);
    for (const auto* result : {&thin, &full}) {
        const auto& curve = result->curve;
        EXPECT_EQ(curve.front().threshold, -kInf);
        EXPECT_EQ(curve.front().tpr, 0.0);
        EXPECT_EQ(curve.front().fpr, 0.0);
        EXPECT_EQ(curve.back().tpr, 1.0);
        EXPECT_EQ(curve.back().fpr, 1.0);
        for (std::size_t k = 1; k < curve.size(); ++k) {
            EXPECT_GT(curve[k].threshold, curve[k - 1].threshold);
            EXPECT_GE(curve[k].tpr, curve[k - 1].tpr);
            EXPECT_GE(curve[k].fpr, curve[k - 1].fpr);
            if (result == &thin) {
                EXPECT_EQ(curve[k].confusion, ConfusionAt(pairs, curve[k].threshold));
            }
            EXPECT_DOUBLE_EQ(curve[k].precision, Precision(curve[k].confusion));
        }
    }
}

TEST(Pairwise, BestThresholdsEqualBruteForceSearch) {
    for (const unsigned seed : {1u, 2u, 3u, 4u}) {
        const auto pairs = RandomPairs(seed, 1500, 0.05 * seed, seed % 2 == 0 ? 40 : 0, 0.15);
        const PairwiseEvaluation result = EvaluatePairs(pairs);
        for (const auto& [actual, metric] :
             {std::pair{result.best_mcc, &Mcc}, std::pair{result.best_f1, &F1}}) {
            const BestThreshold expected = BruteBest(pairs, metric);
            EXPECT_EQ(actual.threshold, expected.threshold) << "seed " << seed;
            EXPECT_EQ(actual.score, expected.score);
            EXPECT_EQ(actual.confusion, expected.confusion);
        }
    }
}

TEST(Pairwise, ConfusionsAtMatchesConfusionAt) {
    const auto pairs = RandomPairs(5, 2000, 0.3, 20, 0.1);
    const std::vector<double> taus{0.5, -kInf, 0.05, kInf, 0.3, 0.3, -0.2, 1.0};
    const auto all = ConfusionsAt(pairs, taus);
    ASSERT_EQ(all.size(), taus.size());
    for (std::size_t k = 0; k < taus.size(); ++k) EXPECT_EQ(all[k], ConfusionAt(pairs, taus[k]));
    EXPECT_THROW(ConfusionAt(pairs, std::numeric_limits<double>::quiet_NaN()), core::Error);
}

TEST(Pairwise, UnscoredPairsAreNeverDetected) {
    constexpr float kUnscored = std::numeric_limits<float>::infinity();
    std::vector<ScoredPair> pairs{
        {0, 5, 0.1f, true}, {0, 6, kUnscored, true}, {1, 6, 0.7f, false}, {2, 7, kUnscored, false}};
    const PairwiseEvaluation result = EvaluatePairs(pairs);
    EXPECT_EQ(result.pairs, 4u);
    EXPECT_EQ(result.distinct_thresholds, 2u);
    EXPECT_EQ(result.best_mcc.threshold, static_cast<double>(0.1f));
    EXPECT_EQ(result.best_mcc.confusion, (Confusion{1, 0, 2, 1}));
    // The sweep ends at the largest finite distance, short of (1, 1).
    EXPECT_EQ(result.curve.back().threshold, static_cast<double>(0.7f));
    EXPECT_EQ(result.curve.back().confusion, (Confusion{1, 1, 1, 1}));
    for (const double tau : {1e30, kInf})
        EXPECT_EQ(ConfusionAt(pairs, tau), (Confusion{1, 1, 1, 1}));
    const std::vector<double> taus{kInf, static_cast<double>(0.1f)};
    EXPECT_EQ(ConfusionsAt(pairs, taus), (std::vector<Confusion>{{1, 1, 1, 1}, {1, 0, 2, 1}}));
    // ROC: (0,0) -> (0, 1/2) -> (1/2, 1/2), and no further: the unscored pairs add no area.
    EXPECT_DOUBLE_EQ(*result.roc_auc, 0.25);
}

// A detector that lists only two non-loops and omits the three loops: calling everything a loop
// (tau = +inf) would score F1 3/4 and MCC 0, above any listed distance. Omitted pairs are never
// detected, so the optimum is a listed distance, worse as it is.
TEST(Pairwise, OmittedPairsNeverMakeTheBestThresholdInfinite) {
    constexpr float kOmitted = std::numeric_limits<float>::infinity();
    std::vector<ScoredPair> pairs{{0, 4, 0.1f, false},
                                  {1, 5, 0.2f, false},
                                  {0, 6, kOmitted, true},
                                  {1, 6, kOmitted, true},
                                  {2, 6, kOmitted, true}};
    const PairwiseEvaluation result = EvaluatePairs(pairs);
    // At 0.1: TP 0, FP 1, TN 1, FN 3: F1 0, MCC -3 / sqrt(1 * 3 * 2 * 4). At 0.2 MCC is -1.
    EXPECT_EQ(result.best_f1.threshold, static_cast<double>(0.1f));
    EXPECT_EQ(result.best_f1.score, 0.0);
    EXPECT_EQ(result.best_mcc.threshold, static_cast<double>(0.1f));
    EXPECT_DOUBLE_EQ(result.best_mcc.score, -3.0 / std::sqrt(24.0));
    EXPECT_EQ(result.best_mcc.confusion, (Confusion{0, 1, 1, 3}));
    for (const CurvePoint& point : result.curve) EXPECT_LT(point.threshold, kInf);
    EXPECT_EQ(result.curve.back().confusion.tp, 0u);
}

TEST(Pairwise, WithOmittedPairsTheOptimaEqualBruteForceOverFiniteDistances) {
    for (const unsigned seed : {7u, 8u, 9u}) {
        auto pairs = RandomPairs(seed, 3000, 0.3, seed % 2 == 0 ? 30 : 0, 0.2);
        // Omit most loops (the detector listed only its best candidates).
        for (std::size_t k = 0; k < pairs.size(); ++k) {
            if (k % 5 != 0 && (pairs[k].loop || k % 3 == 0)) {
                pairs[k].distance = std::numeric_limits<float>::infinity();
            }
        }
        PairwiseConfig all_points;
        all_points.max_curve_points = 0;
        const PairwiseEvaluation result = EvaluatePairs(pairs, all_points);
        for (const auto& [actual, metric] :
             {std::pair{result.best_mcc, &Mcc}, std::pair{result.best_f1, &F1}}) {
            const BestThreshold expected = BruteBest(pairs, metric);
            EXPECT_EQ(actual.threshold, expected.threshold) << "seed " << seed;
            EXPECT_EQ(actual.confusion, expected.confusion);
        }
        for (std::size_t k = 1; k < result.curve.size(); ++k) {
            EXPECT_LT(result.curve[k].threshold, kInf);
            EXPECT_EQ(result.curve[k].confusion, ConfusionAt(pairs, result.curve[k].threshold));
        }
        EXPECT_LT(result.curve.back().tpr, 1.0);
        EXPECT_EQ(result.curve.back().confusion, ConfusionAt(pairs, kInf));
    }
}

TEST(Pairwise, WithoutAFiniteDistanceNothingIsEverDetected) {
    constexpr float kOmitted = std::numeric_limits<float>::infinity();
    std::vector<ScoredPair> pairs{{0, 4, kOmitted, true}, {1, 5, kOmitted, false}};
    const PairwiseEvaluation result = EvaluatePairs(pairs);
    EXPECT_EQ(result.distinct_thresholds, 0u);
    ASSERT_EQ(result.curve.size(), 1u);
    EXPECT_EQ(result.best_f1.threshold, -kInf);
    EXPECT_EQ(result.best_f1.confusion, (Confusion{0, 0, 1, 1}));
    EXPECT_EQ(result.best_mcc.score, 0.0);
    EXPECT_EQ(*result.roc_auc, 0.0);
    EXPECT_EQ(ConfusionAt(pairs, kInf), (Confusion{0, 0, 1, 1}));
}

TEST(Pairwise, DegenerateAndBadInputs) {
    std::vector<ScoredPair> no_loops{{0, 3, 0.2f, false}, {0, 4, 0.1f, false}};
    const PairwiseEvaluation result = EvaluatePairs(no_loops);
    EXPECT_FALSE(result.roc_auc.has_value());
    EXPECT_EQ(result.best_mcc.score, 0.0);
    EXPECT_EQ(result.best_mcc.threshold, static_cast<double>(0.1f));  // the smallest on ties
    std::vector<ScoredPair> only_loops{{0, 3, 0.2f, true}};
    EXPECT_FALSE(EvaluatePairs(only_loops).roc_auc.has_value());
    EXPECT_THROW(EvaluatePairs({}), core::EmptyInputError);
    std::vector<ScoredPair> nan{{0, 3, std::numeric_limits<float>::quiet_NaN(), true}};
    EXPECT_THROW(EvaluatePairs(nan), core::Error);
    for (const std::size_t points : {1u, 2u}) {
        PairwiseConfig config;
        config.max_curve_points = points;
        EXPECT_THROW(config.Validate(), core::ConfigError);
        EXPECT_THROW(EvaluatePairs(only_loops, config), core::ConfigError);
    }
}

}  // namespace
}  // namespace lidarloop::eval

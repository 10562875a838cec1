// The streamed evaluation against the pairs in memory (CollectPairs, EvaluatePairs,
// ConfusionsAt, LearnOnFirstPart, BestMatchesFromCondensed): every figure must be the same
// double, on random sequences with ties, unscored pairs, gaps and thinned curves.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "eval_test_utils.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/detail/slot_counts.hpp"
#include "lidarloop/eval/pairwise.hpp"
#include "lidarloop/eval/streamed_pairwise.hpp"
#include "test_utils.hpp"

namespace lidarloop::eval {
namespace {

struct Case {
    unsigned seed = 1;
    std::size_t scans = 120;
    int levels = 0;          // distances rounded to this many values (ties); 0: continuous
    double unscored = 0.0;   // fraction of +inf pairs
    double gap_scans = 0.0;  // ground-truth minimum gap
    std::size_t curve_points = 1000;
    Criterion criterion = Criterion::kMcc;
    double informative = 0.7;  // how much loops are closer than other pairs (0: noise)
};

struct Sequence {
    GroundTruth truth;
    std::vector<float> condensed;
};

Sequence MakeSequence(const Case& c) {
    GroundTruthConfig rule;
    rule.min_gap = core::MinGap{c.gap_scans, core::MinGap::Unit::kScans};
    Sequence s{BuildGroundTruth(test::RandomTrajectory(c.seed, c.scans), rule), {}};
    std::mt19937 rng(c.seed + 1000);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (std::size_t i = 0; i < c.scans; ++i) {
        for (std::size_t j = i + 1; j < c.scans; ++j) {
            double d = unit(rng) + (s.truth.IsLoop(i, j) ? -c.informative : 0.0);
            if (c.levels > 0) d = std::round(d * c.levels) / c.levels;
            s.condensed.push_back(unit(rng) < c.unscored ? test::kInfFloat : static_cast<float>(d));
        }
    }
    return s;
}

PairDistance DistanceOf(const Sequence& s) {
    const std::size_t n = s.truth.size();
    return [&s, n](std::size_t i, std::size_t j) { return s.condensed[CondensedIndex(n, i, j)]; };
}

StreamedRequest RequestOf(const Case& c) {
    StreamedRequest request;
    request.pairwise.max_curve_points = c.curve_points;
    request.thresholds = {0.3, -1.0, 0.0, 0.5, 2.0, 0.25};
    request.learning = ThresholdLearningConfig{0.5, c.criterion};
    return request;
}

void ExpectSameBest(const BestThreshold& a, const BestThreshold& b) {
    EXPECT_EQ(a.threshold, b.threshold);
    EXPECT_EQ(a.score, b.score);
    EXPECT_EQ(a.confusion, b.confusion);
}

void ExpectSameMatches(const std::vector<BestMatch>& a, const std::vector<BestMatch>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
        EXPECT_EQ(a[k].match, b[k].match) << "scan " << k;
        EXPECT_EQ(a[k].distance, b[k].distance) << "scan " << k;
        EXPECT_EQ(a[k].second_distance, b[k].second_distance) << "scan " << k;
    }
}

// Every figure of the streamed result equals the pairs-in-memory figure exactly.
void ExpectEqualToPairsInMemory(const Case& c, const Sequence& s, const StreamedResult& got) {
    const std::vector<ScoredPair> pairs = CollectPairs(s.condensed, s.truth);
    const StreamedRequest request = RequestOf(c);
    const PairwiseEvaluation want = EvaluatePairs(pairs, request.pairwise);
    EXPECT_EQ(got.pairwise.pairs, want.pairs);
    EXPECT_EQ(got.pairwise.positives, want.positives);
    EXPECT_EQ(got.pairwise.negatives, want.negatives);
    EXPECT_EQ(got.pairwise.distinct_thresholds, want.distinct_thresholds);
    EXPECT_EQ(got.pairwise.roc_auc, want.roc_auc);
    ExpectSameBest(got.pairwise.best_mcc, want.best_mcc);
    ExpectSameBest(got.pairwise.best_f1, want.best_f1);
    ASSERT_EQ(got.pairwise.curve.size(), want.curve.size());
    for (std::size_t k = 0; k < want.curve.size(); ++k) {
        const CurvePoint& g = got.pairwise.curve[k];
        const CurvePoint& w = want.curve[k];
        EXPECT_EQ(g.threshold, w.threshold) << "point " << k;
        EXPECT_EQ(g.confusion, w.confusion) << "point " << k;
        EXPECT_EQ(g.tpr, w.tpr) << "point " << k;
        EXPECT_EQ(g.fpr, w.fpr) << "point " << k;
        EXPECT_EQ(g.precision, w.precision) << "point " << k;
    }
    EXPECT_EQ(got.at_thresholds, ConfusionsAt(pairs, request.thresholds));
    std::optional<ThresholdTransfer> learnt;
    try {
        learnt = LearnOnFirstPart(pairs, s.truth.size(), *request.learning);
    } catch (const core::EmptyInputError&) {
    }
    ASSERT_EQ(got.learnt.has_value(), learnt.has_value());
    if (learnt) {
        EXPECT_EQ(got.learnt->threshold, learnt->threshold);
        EXPECT_EQ(got.learnt->train_score, learnt->train_score);
        EXPECT_EQ(got.learnt->train, learnt->train);
        EXPECT_EQ(got.learnt->test, learnt->test);
        EXPECT_EQ(got.learnt->test_f1, learnt->test_f1);
        EXPECT_EQ(got.learnt->test_mcc, learnt->test_mcc);
    }
    ExpectSameMatches(got.best_matches, BestMatchesFromCondensed(s.condensed, s.truth));
}

StreamedResult StreamAll(const Case& c, const Sequence& s) {
    StreamedPairwise evaluation(s.truth, ScorePositives(s.truth, DistanceOf(s)), RequestOf(c));
    return StreamSerially(evaluation, s.truth.size(), DistanceOf(s));
}

TEST(StreamedPairwise, EqualsPairsInMemoryOnRandomSequences) {
    const std::vector<Case> cases = {
        {1, 120, 0, 0.0, 0.0, 1000, Criterion::kMcc, 0.7},
        {2, 150, 8, 0.0, 0.0, 1000, Criterion::kF1, 0.7},   // many ties
        {3, 130, 0, 0.1, 5.0, 1000, Criterion::kMcc, 0.5},  // unscored pairs, gap
        {4, 140, 20, 0.05, 3.0, 12, Criterion::kF1, 0.3},   // thinned hard, ties
        {5, 100, 0, 0.0, 0.0, 3, Criterion::kMcc, 0.7},     // fewest points
        {6, 160, 50, 0.02, 0.0, 40, Criterion::kMcc, 0.9},
        {7, 110, 4, 0.3, 10.0, 7, Criterion::kF1, 0.2},
        {8, 90, 0, 0.0, 0.0, 25, Criterion::kMcc, -0.5},     // a detector worse than chance
        {9, 780, 30, 0.01, 0.0, 200, Criterion::kMcc, 0.6},  // > 2^18 pairs: several batches
    };
    for (const Case& c : cases) {
        SCOPED_TRACE("seed " + std::to_string(c.seed));
        const Sequence s = MakeSequence(c);
        const StreamedResult got = StreamAll(c, s);
        ExpectEqualToPairsInMemory(c, s, got);
    }
}

TEST(StreamedPairwise, PairsSpreadOverSinksInAnyOrderGiveTheSameResult) {
    const Case c{11, 100, 10, 0.05, 2.0, 30, Criterion::kMcc, 0.6};
    const Sequence s = MakeSequence(c);
    const std::size_t n = s.truth.size();
    std::vector<std::pair<std::size_t, std::size_t>> order;
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n; ++j) order.emplace_back(i, j);
    }
    StreamedPairwise evaluation(s.truth, ScorePositives(s.truth, DistanceOf(s)), RequestOf(c));
    std::mt19937 rng(5);
    while (!evaluation.finished()) {
        std::shuffle(order.begin(), order.end(), rng);
        std::vector<StreamedPairwise::Sink> sinks;
        for (int k = 0; k < 3; ++k) sinks.push_back(evaluation.NewSink());
        for (std::size_t k = 0; k < order.size(); ++k) {
            const auto [i, j] = order[k];
            sinks[k % 3].Add(i, j, s.condensed[CondensedIndex(n, i, j)]);
        }
        for (auto& sink : sinks) evaluation.Merge(sink);
        evaluation.EndPass();
    }
    ExpectEqualToPairsInMemory(c, s, evaluation.Result());
}

// The first pass's findings move whole into the second (no field copied by hand can be left
// behind), and a sink counts for the pass that made it only.
TEST(StreamedPairwise, ASinkBelongsToThePassThatMadeIt) {
    const Case c{12, 60, 0, 0.0, 0.0, 30, Criterion::kMcc, 0.6};
    const Sequence s = MakeSequence(c);
    const std::size_t n = s.truth.size();
    StreamedPairwise evaluation(s.truth, ScorePositives(s.truth, DistanceOf(s)), RequestOf(c));
    const auto stream = [&](StreamedPairwise::Sink& sink) {
        for (std::size_t i = 0; i < n; ++i) {
            for (std::size_t j = i + 1; j < n; ++j) sink.Add(i, j, DistanceOf(s)(i, j));
        }
    };
    StreamedPairwise::Sink first = evaluation.NewSink();
    stream(first);
    evaluation.Merge(first);
    evaluation.EndPass();
    EXPECT_EQ(evaluation.pass(), 2);
    EXPECT_THROW(evaluation.Merge(first), core::Error);  // counted once, in its own pass
    StreamedPairwise::Sink second = evaluation.NewSink();
    stream(second);
    evaluation.Merge(second);
    evaluation.EndPass();
    ASSERT_TRUE(evaluation.finished());
    EXPECT_THROW(evaluation.NewSink(), core::Error);
    EXPECT_THROW(evaluation.Merge(second), core::Error);
    ExpectEqualToPairsInMemory(c, s, evaluation.Result());
}

TEST(StreamedPairwise, EveryPairUnscoredOrNoLoops) {
    Case c{21, 40, 0, 1.0, 0.0, 1000, Criterion::kMcc, 0.7};
    Sequence s = MakeSequence(c);
    ExpectEqualToPairsInMemory(c, s, StreamAll(c, s));
    // No loops: a ground truth whose distance is tiny.
    c.unscored = 0.0;
    s = MakeSequence(c);
    GroundTruthConfig rule;
    rule.distance_m = 1e-6;
    s.truth = BuildGroundTruth(test::RandomTrajectory(c.seed, c.scans), rule);
    ExpectEqualToPairsInMemory(c, s, StreamAll(c, s));
}

TEST(StreamedPairwise, BadInputGivesTypedErrors) {
    const Case c{31, 30};
    Sequence s = MakeSequence(c);
    StreamedRequest all_points = RequestOf(c);
    all_points.pairwise.max_curve_points = 0;
    EXPECT_THROW(StreamedPairwise(s.truth, {}, all_points), core::ConfigError);
    StreamedRequest nan_threshold = RequestOf(c);
    nan_threshold.thresholds.push_back(std::numeric_limits<double>::quiet_NaN());
    EXPECT_THROW(StreamedPairwise(s.truth, {}, nan_threshold), core::Error);
    s.condensed[17] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(StreamAll(c, s), core::Error);
    const Sequence one = MakeSequence({32, 1});
    EXPECT_THROW(StreamAll(c, one), core::EmptyInputError);
}

// The 4-byte slots carry past 2^32 (a slot of more than 4.3e9 negatives: the pairs above every
// positive's distance at 100,000 scans come near), and a carry stays with its slot.
TEST(SlotCounts, CountPast32BitsExactly) {
    detail::SlotCounts slots;
    slots.Assign(3);
    constexpr std::uint64_t kStep = (std::uint64_t{1} << 31) + 12345;  // below 2^32, as Add wants
    std::uint64_t want = 0;
    for (int k = 0; k < 5; ++k) {
        slots.Add(1, kStep);
        want += kStep;
        EXPECT_EQ(slots[1], want) << "after " << k + 1 << " adds";
    }
    slots.Add(2, 7);
    EXPECT_EQ(slots.front(), 0u);
    EXPECT_EQ(slots.back(), 7u);
    EXPECT_GT(want, std::uint64_t{1} << 33);
    slots.Assign(3);
    EXPECT_EQ(slots[1], 0u);
}

}  // namespace
}  // namespace lidarloop::eval

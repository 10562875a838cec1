#include <algorithm>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "eval/eval_test_utils.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/pairwise.hpp"
#include "lidarloop/eval/per_scan.hpp"
#include "test_utils.hpp"

namespace lidarloop::eval {
namespace {

using test::kInf;

// Ten scans on a line; scan 5 revisits scan 0 (2 m away) and scan 7 revisits scan 3.
GroundTruth TenPoseLineTruth() {
    const double x[] = {0, 100, 200, 300, 400, 2, 500, 302, 600, 700};
    std::vector<core::StampedPose> poses;
    for (int i = 0; i < 10; ++i) poses.push_back(test::MakePose(i, x[i], 0.0));
    GroundTruthConfig config;
    config.distance_m = 10.0;  // t_r
    config.min_gap = {2.0, core::MinGap::Unit::kScans};
    return BuildGroundTruth(poses, config);
}

// One scan per label of Magnusson table I at t_d = 1 (and more true negatives).
std::vector<BestMatch> LineMatches() {
    return {
        {5, 0.10, kInf},  // 0: similar, overlapping, match at the same place -> true positive
        {8, 0.30, kInf},  // 1: similar, not overlapping                       -> false positive
        {6, 5.00, kInf},  // 2: not similar, not overlapping                   -> true negative
        {7, 5.00, kInf},  // 3: not similar, overlapping (with 7)              -> false negative
        {9, 5.00, kInf},  // 4: true negative
        {9, 0.20, kInf},  // 5: similar, overlapping, but 9 is 698 m away      -> mismatch
        {2, 5.00, kInf},  // 6: true negative
        {3, 0.25, kInf},  // 7: true positive
        {1, 5.00, kInf},  // 8: true negative
        {4, 4.00, kInf},  // 9: true negative
    };
}

TEST(PerScan, HandMadeSequenceFollowsTableI) {
    const GroundTruth truth = TenPoseLineTruth();
    const auto matches = LineMatches();
    const auto labels = LabelScans(matches, truth, 1.0);
    using L = ScanLabel;
    const std::vector<ScanLabel> expected{
        L::kTruePositive, L::kFalsePositive, L::kTrueNegative, L::kFalseNegative, L::kTrueNegative,
        L::kMismatch,     L::kTrueNegative,  L::kTruePositive, L::kTrueNegative,  L::kTrueNegative};
    EXPECT_EQ(labels, expected);
    const TaxonomyCounts counts = CountLabels(labels);
    EXPECT_EQ(counts, (TaxonomyCounts{2, 1, 1, 5, 1}));
    EXPECT_EQ(counts.Overlapping(), 4u);
    EXPECT_EQ(counts.NonOverlapping(), 6u);
    EXPECT_DOUBLE_EQ(counts.Recall(), 0.5);
    EXPECT_DOUBLE_EQ(counts.FalsePositiveRate(), 1.0 / 6.0);
    // "sigma' < t_d" is strict: at t_d = 0.1 scan 0 is not yet similar.
    EXPECT_EQ(LabelScans(matches, truth, 0.1)[0], L::kFalseNegative);
    EXPECT_EQ(LabelScans(matches, truth, kInf)[3], L::kTruePositive);
    EXPECT_EQ(ToString(L::kTruePositive), "true_positive");
    EXPECT_EQ(ToString(L::kMismatch), "mismatch");
    EXPECT_EQ(ToString(L::kFalsePositive), "false_positive");
    EXPECT_EQ(ToString(L::kTrueNegative), "true_negative");
    EXPECT_EQ(ToString(L::kFalseNegative), "false_negative");
}

TEST(PerScan, ZeroErrorPointWithAndWithoutMismatches) {
    const GroundTruth truth = TenPoseLineTruth();
    const auto matches = LineMatches();
    const PerScanEvaluation strict = EvaluatePerScan(matches, truth);
    EXPECT_EQ(strict.overlapping, 4u);
    EXPECT_EQ(strict.non_overlapping, 6u);
    EXPECT_EQ(strict.zero_error.t_d, 0.20);  // scan 5, the mismatch, would be next
    EXPECT_EQ(strict.zero_error.last_true_positive_distance, 0.10);
    EXPECT_EQ(strict.zero_error.counts.true_positive, 1u);
    EXPECT_DOUBLE_EQ(strict.zero_error.recall, 0.25);

    PerScanConfig config;
    config.mismatches_are_errors = false;
    const PerScanEvaluation lenient = EvaluatePerScan(matches, truth, config);
    EXPECT_EQ(lenient.zero_error.t_d, 0.30);  // scan 1, the false positive, would be next
    EXPECT_EQ(lenient.zero_error.last_true_positive_distance, 0.25);
    EXPECT_EQ(lenient.zero_error.counts, (TaxonomyCounts{2, 1, 0, 6, 1}));
    EXPECT_DOUBLE_EQ(lenient.zero_error.recall, 0.5);

    // Fig. 1: one point per distinct distance, then +inf; each equals labelling at that t_d.
    const std::vector<double> thresholds{0.1, 0.2, 0.25, 0.3, 4.0, 5.0, kInf};
    ASSERT_EQ(strict.curve.size(), thresholds.size());
    for (std::size_t k = 0; k < thresholds.size(); ++k) {
        EXPECT_EQ(strict.curve[k].t_d, thresholds[k]);
        EXPECT_EQ(strict.curve[k].counts, CountLabels(LabelScans(matches, truth, thresholds[k])));
    }
}

TEST(PerScan, HeadingRuleDecidesOverlapAndMismatch) {
    // Scan 0 faces east at x = 0; scan 3 is at the same place facing west; scan 6 facing east.
    std::vector<core::StampedPose> poses{
        test::MakePose(0, 0, 0, 0.0), test::MakePose(1, 50, 0),
        test::MakePose(2, 100, 0),    test::MakePose(3, 1, 0, std::numbers::pi),
        test::MakePose(4, 150, 0),    test::MakePose(5, 200, 0),
        test::MakePose(6, 2, 0, 0.05)};
    GroundTruthConfig config;
    config.distance_m = 5.0;
    config.max_heading_deg = 20.0;
    config.min_gap = {1.0, core::MinGap::Unit::kScans};
    const GroundTruth truth = BuildGroundTruth(poses, config);
    EXPECT_TRUE(truth.Overlapping(0));   // with 6
    EXPECT_FALSE(truth.Overlapping(3));  // 0 and 6 face the other way
    std::vector<BestMatch> matches(7, BestMatch{});
    matches[0] = {3, 0.1, kInf};  // the same place but looking the other way: a mismatch
    matches[3] = {0, 0.1, kInf};  // not overlapping at all: a false positive
    matches[6] = {0, 0.1, kInf};  // a true positive
    const auto labels = LabelScans(matches, truth, 1.0);
    EXPECT_EQ(labels[0], ScanLabel::kMismatch);
    EXPECT_EQ(labels[3], ScanLabel::kFalsePositive);
    EXPECT_EQ(labels[6], ScanLabel::kTruePositive);
    EXPECT_EQ(labels[1], ScanLabel::kTrueNegative);  // no match at all is never similar
}

// Distances that follow the ground truth loosely: near places look alike, plus noise.
std::vector<float> NoisyCondensed(const std::vector<core::StampedPose>& poses, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> noise(0.0, 1.0);
    const std::size_t n = poses.size();
    std::vector<float> condensed(CondensedSize(n));
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n; ++j) {
            const double meters =
                (poses[i].T_world_sensor.translation() - poses[j].T_world_sensor.translation())
                    .norm();
            const double d = std::min(1.0, meters / 50.0) + 0.4 * noise(rng);
            condensed[CondensedIndex(n, i, j)] = static_cast<float>(std::round(d * 200) / 200);
        }
    }
    return condensed;
}

TEST(PerScan, BestMatchesEqualBruteForce) {
    const auto poses = test::RandomTrajectory(6, 250);
    GroundTruthConfig config;
    config.min_gap = {30.0, core::MinGap::Unit::kScans};
    const GroundTruth truth = BuildGroundTruth(poses, config);
    const auto condensed = NoisyCondensed(poses, 2);
    const auto best = BestMatchesFromCondensed(condensed, truth);
    const std::size_t n = poses.size();
    for (std::size_t i = 0; i < n; ++i) {
        std::vector<std::pair<double, std::size_t>> candidates;
        for (std::size_t j = 0; j < n; ++j) {
            if (!truth.Comparable(i, j)) continue;
            const std::size_t at = i < j ? CondensedIndex(n, i, j) : CondensedIndex(n, j, i);
            candidates.emplace_back(condensed[at], j);
        }
        std::sort(candidates.begin(), candidates.end());  // ties: smaller index first
        ASSERT_GE(candidates.size(), 2u);
        EXPECT_EQ(best[i].match, candidates[0].second) << "scan " << i;
        EXPECT_EQ(best[i].distance, candidates[0].first);
        EXPECT_EQ(best[i].second_distance, candidates[1].first);
    }
}

TEST(PerScan, SweepEqualsLabellingAtEveryThreshold) {
    for (const unsigned seed : {1u, 2u, 3u}) {
        const auto poses = test::RandomTrajectory(seed + 10, 300);
        GroundTruthConfig config;
        config.min_gap = {20.0, core::MinGap::Unit::kScans};
        const GroundTruth truth = BuildGroundTruth(poses, config);
        const auto matches = BestMatchesFromCondensed(NoisyCondensed(poses, seed), truth);
        const PerScanEvaluation result = EvaluatePerScan(matches, truth);
        double zero_error_t_d = -kInf;
        TaxonomyCounts zero_error_counts;
        for (const auto& point : result.curve) {
            const TaxonomyCounts counts = CountLabels(LabelScans(matches, truth, point.t_d));
            EXPECT_EQ(point.counts, counts) << "t_d " << point.t_d;
            if (counts.false_positive == 0 && counts.mismatch == 0) {
                zero_error_t_d = point.t_d;
                zero_error_counts = counts;
            }
        }
        EXPECT_EQ(result.zero_error.t_d, zero_error_t_d) << "seed " << seed;
        EXPECT_EQ(result.zero_error.counts, zero_error_counts);
        EXPECT_EQ(result.curve.back().t_d, kInf);
        for (std::size_t k = 1; k < result.curve.size(); ++k) {
            EXPECT_GT(result.curve[k].t_d, result.curve[k - 1].t_d);
        }
    }
}

TEST(PerScan, RejectsInconsistentInput) {
    const GroundTruth truth = TenPoseLineTruth();
    auto matches = LineMatches();
    EXPECT_THROW(LabelScans(matches, truth, std::numeric_limits<double>::quiet_NaN()), core::Error);
    matches[0].match = 1;  // inside the minimum gap of scan 0
    EXPECT_THROW(LabelScans(matches, truth, 1.0), core::Error);
    matches[0].match = 0;  // itself
    EXPECT_THROW(EvaluatePerScan(matches, truth), core::Error);
    matches[0] = {kNoScan, 0.5, kInf};  // no match but a distance
    EXPECT_THROW(EvaluatePerScan(matches, truth), core::Error);
    matches.pop_back();
    EXPECT_THROW(EvaluatePerScan(matches, truth), core::Error);
    EXPECT_THROW(BestMatchesFromCondensed(std::vector<float>(3), truth), core::Error);
}

}  // namespace
}  // namespace lidarloop::eval

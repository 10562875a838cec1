// A results file that lists only some pairs (another detector's top-1 per scan), scored on a
// hand-made ground truth: the pairs and scans it leaves out are never detected, and files with
// too little in them still give a report.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "eval/eval_test_utils.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/app/evaluation_report.hpp"
#include "lidarloop/app/metrics_json.hpp"
#include "lidarloop/io/read_error.hpp"
#include "test_utils.hpp"

namespace lidarloop {
namespace {

using test::kInf;

// Eight scans at three places 100 m apart: A = {0, 2, 4, 6}, B = {1, 3, 5}, C = {7}. Every pair
// of distinct scans is evaluated (gap 0); the same place is a loop: 6 + 3 = 9 loops, 19 others.
eval::GroundTruth ThreePlaces() {
    const double x_m[] = {0.0, 100.0, 0.0, 100.0, 0.0, 100.0, 0.0, 200.0};
    std::vector<core::StampedPose> poses;
    for (int i = 0; i < 8; ++i) poses.push_back(test::MakePose(i, x_m[i], 0.0));
    eval::GroundTruthConfig rule;
    rule.min_gap.value = 0.0;
    return eval::BuildGroundTruth(poses, rule);
}

// The detector's best earlier scan for queries 1-5. Scan 0 has no earlier scan; 6 and 7 are
// left out (no candidate passed the detector's own test). 23 of the 28 pairs are omitted,
// 7 of them loops.
constexpr const char* kTopOne =
    "query,match,distance\n"
    "1,0,0.5\n"   // B-A: wrong
    "2,1,0.45\n"  // A-B: wrong (its loop with 0 is omitted)
    "3,1,0.2\n"   // B-B: right
    "4,0,0.1\n"   // A-A: right
    "5,4,0.3\n";  // B-A: wrong

app::MethodEvaluation EvaluateCsv(const test::TempDir& dir, const std::string& csv,
                                  const eval::GroundTruth& truth,
                                  const eval::ThresholdLearningConfig& learning = {}) {
    test::WriteFile(dir / "top1.csv", csv);
    return app::EvaluateMatrix("results:top1", app::MatrixOfResults(dir / "top1.csv", 8), truth,
                               learning, std::nullopt);
}

double F(float distance) { return static_cast<double>(distance); }

TEST(PartialResults, OmittedPairsAreNeverDetectedInTheSweep) {
    const test::TempDir dir;
    const eval::PairwiseEvaluation p = EvaluateCsv(dir, kTopOne, ThreePlaces()).pairwise;
    EXPECT_EQ(p.pairs, 28u);
    EXPECT_EQ(p.positives, 9u);
    EXPECT_EQ(p.distinct_thresholds, 5u);
    // At 0.2 the two right pairs are detected: TP 2, FP 0, TN 19, FN 7. Calling every pair a
    // loop would give F1 18 / 37 = 0.486 > 4 / 11, but the omitted pairs are never detected.
    EXPECT_EQ(p.best_f1.threshold, F(0.2f));
    EXPECT_DOUBLE_EQ(p.best_f1.score, 4.0 / 11.0);
    EXPECT_EQ(p.best_f1.confusion, (eval::Confusion{2, 0, 19, 7}));
    EXPECT_EQ(p.best_mcc.threshold, F(0.2f));
    EXPECT_DOUBLE_EQ(p.best_mcc.score, 38.0 / std::sqrt(2.0 * 9.0 * 19.0 * 26.0));
    // The curve ends at the largest listed distance: TP 2, FP 3 (FPR 3/19, TPR 2/9).
    ASSERT_EQ(p.curve.size(), 6u);
    EXPECT_EQ(p.curve.back().threshold, F(0.5f));
    EXPECT_EQ(p.curve.back().confusion, (eval::Confusion{2, 3, 16, 7}));
    // The ROC curve climbs to TPR 2/9 at FPR 0, then runs flat to FPR 3/19.
    EXPECT_NEAR(*p.roc_auc, 3.0 / 19.0 * 2.0 / 9.0, 1e-12);
}

TEST(PartialResults, TheLearntThresholdIsAListedDistance) {
    const test::TempDir dir;
    const app::MethodEvaluation e = EvaluateCsv(dir, kTopOne, ThreePlaces());
    // Trained on the pairs whose later scan is < 4: (1,3) is the one right pair listed, (0,1)
    // and (1,2) the wrong ones; the loop (0,2) is omitted.
    ASSERT_TRUE(e.learnt.has_value());
    EXPECT_EQ(e.learnt->threshold, F(0.2f));
    EXPECT_EQ(e.learnt->train, (eval::Confusion{1, 0, 4, 1}));
    EXPECT_DOUBLE_EQ(e.learnt->train_score, 4.0 / std::sqrt(40.0));
    // Tested on the 22 pairs with a later scan >= 4 (7 loops): only (0,4) is detected.
    EXPECT_EQ(e.learnt->test, (eval::Confusion{1, 0, 15, 6}));
    EXPECT_DOUBLE_EQ(e.learnt->test_f1, 0.25);
    EXPECT_DOUBLE_EQ(e.learnt->test_mcc, 15.0 / std::sqrt(2205.0));
}

TEST(PartialResults, AFirstPartWithOnlyWrongPairsStillLearnsAListedDistance) {
    const test::TempDir dir;
    eval::ThresholdLearningConfig learning;
    learning.train_fraction = 0.375;  // train on the pairs whose later scan is < 3
    const app::MethodEvaluation e = EvaluateCsv(dir, kTopOne, ThreePlaces(), learning);
    // Training lists only the wrong (0,1) at 0.5 and (1,2) at 0.45 and omits the loop (0,2).
    // Calling all three loops would give MCC 0; the best listed distance gives -1/2 at 0.45.
    ASSERT_TRUE(e.learnt.has_value());
    EXPECT_EQ(e.learnt->threshold, F(0.45f));
    EXPECT_EQ(e.learnt->train, (eval::Confusion{0, 1, 1, 1}));
    EXPECT_DOUBLE_EQ(e.learnt->train_score, -0.5);
    // Tested on the other 25 pairs (8 loops): (1,3), (0,4) and the wrong (4,5) are detected.
    EXPECT_EQ(e.learnt->test, (eval::Confusion{2, 1, 16, 6}));
    EXPECT_DOUBLE_EQ(e.learnt->test_f1, 4.0 / 11.0);
    EXPECT_DOUBLE_EQ(e.learnt->test_mcc, 26.0 / std::sqrt(3.0 * 8.0 * 17.0 * 22.0));
}

TEST(PartialResults, AScanTheFileLeavesOutHasNoMatch) {
    const test::TempDir dir;
    const eval::GroundTruth truth = ThreePlaces();
    const app::MethodEvaluation e = EvaluateCsv(dir, kTopOne, truth);
    const std::vector<std::size_t> matches{4, 3, 1, 1, 0, 4, eval::kNoScan, eval::kNoScan};
    ASSERT_EQ(e.best_matches.size(), matches.size());
    for (std::size_t i = 0; i < matches.size(); ++i) EXPECT_EQ(e.best_matches[i].match, matches[i]);
    EXPECT_EQ(e.best_matches[6].distance, kInf);
    // Even at t_d = +inf scan 6 (a place seen before) is a false negative and scan 7 (a new
    // place) a true negative, not a match to some arbitrary scan.
    const auto labels = eval::LabelScans(e.best_matches, truth, kInf);
    EXPECT_EQ(labels[6], eval::ScanLabel::kFalseNegative);
    EXPECT_EQ(labels[7], eval::ScanLabel::kTrueNegative);
    EXPECT_EQ(e.per_scan.overlapping, 7u);
    // Zero errors up to the mismatch of scan 5 at 0.3: scans 0, 1, 3, 4 found, 2, 5, 6 missed.
    EXPECT_EQ(e.per_scan.zero_error.t_d, F(0.3f));
    EXPECT_EQ(e.per_scan.zero_error.counts, (eval::TaxonomyCounts{4, 0, 0, 1, 3}));
    EXPECT_DOUBLE_EQ(e.per_scan.zero_error.recall, 4.0 / 7.0);
    EXPECT_EQ(e.em.values_skipped, 2u);
}

// Nothing listed, one distance for every pair (a yes/no detector), or too few pairs for EM:
// the evaluation and its report go through, without the figures there is nothing for.
TEST(PartialResults, AFileWithTooLittleInItStillGivesAReport) {
    const eval::GroundTruth truth = ThreePlaces();
    for (const std::string csv :
         {"query,match,distance\n", "query,match,distance\n1,0,0\n3,1,0\n5,4,0\n4,0,0\n",
          "query,match,distance\n3,1,0.2\n"}) {
        const test::TempDir dir;
        const app::MethodEvaluation e = EvaluateCsv(dir, csv, truth);
        EXPECT_FALSE(e.em.Fitted()) << csv;
        EXPECT_TRUE(app::MetricsJson(e)["em"].is_null());
        for (const eval::CurvePoint& point : e.pairwise.curve) EXPECT_LT(point.threshold, kInf);
        if (e.learnt) {
            EXPECT_TRUE(std::isfinite(e.learnt->threshold)) << csv;
        }
        const std::vector<app::MethodEvaluation> evaluations{e};
        EXPECT_NO_THROW(app::WriteCurveCsvs(dir.path(), evaluations));
        EXPECT_NO_THROW(app::WriteFigures(dir.path(), truth, evaluations)) << csv;
        EXPECT_NO_THROW(
            app::WriteReport(dir.path(), {"three places", 8, truth.Describe()}, evaluations, {}));
    }
}

TEST(PartialResults, AFileWithNothingListedLearnsNoThreshold) {
    const test::TempDir dir;
    const app::MethodEvaluation e = EvaluateCsv(dir, "query,match,distance\n", ThreePlaces());
    EXPECT_EQ(e.pairwise.distinct_thresholds, 0u);
    EXPECT_EQ(e.pairwise.best_f1.confusion, (eval::Confusion{0, 0, 19, 9}));
    EXPECT_FALSE(e.learnt.has_value());
    EXPECT_EQ(e.per_scan.zero_error.counts.true_positive, 0u);
}

TEST(PartialResults, ADistanceBeyondTheFloatRangeIsAReadError) {
    const test::TempDir dir;
    test::WriteFile(dir / "r.csv", "query,match,distance\n3,1,1e300\n");
    try {
        app::MatrixOfResults(dir / "r.csv", 4);
        FAIL() << "no error";
    } catch (const io::ReadError& e) {
        EXPECT_TRUE(test::Contains(e.what(), "pair (3, 1): the distance is beyond the float"));
    }
}

}  // namespace
}  // namespace lidarloop

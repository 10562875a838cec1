#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "eval/eval_test_utils.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/loop_retrieval.hpp"
#include "test_utils.hpp"

namespace lidarloop::eval {
namespace {

using test::kDeg;
using test::kInf;

core::Transform PoseDeg(double x, double y, double z, double yaw_deg, double pitch_deg = 0.0) {
    core::Transform T = core::Transform::Identity();
    T.translation() = Eigen::Vector3d(x, y, z);
    T.linear() = (Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(pitch_deg * kDeg, Eigen::Vector3d::UnitY()))
                     .toRotationMatrix();
    return T;
}

// Eight scans: out along x (0..4, 20 m apart), then back: 5 revisits 2, 6 revisits 1, 7
// revisits 0, each 1-2 m away. t_r = 5 m, S = 2 scans.
std::vector<core::StampedPose> LinePoses() {
    const double x[] = {0, 20, 40, 60, 80, 42, 21, 1};
    std::vector<core::StampedPose> poses;
    for (int i = 0; i < 8; ++i) poses.push_back(test::MakePose(i, x[i], 0.0, i < 5 ? 0.0 : 3.1));
    return poses;
}

GroundTruth LineTruth() {
    GroundTruthConfig config;
    config.distance_m = 5.0;
    config.min_gap = {2.0, core::MinGap::Unit::kScans};
    return BuildGroundTruth(LinePoses(), config);
}

RankedCandidate Candidate(std::size_t match, bool accepted, double score,
                          std::optional<core::Transform> T_match_query = std::nullopt) {
    return {match, -score, accepted, score, T_match_query};
}

core::Transform TrueMatchQuery(std::size_t match, std::size_t query) {
    const auto poses = LinePoses();
    return TrueRelativePose(poses[match].T_world_sensor, poses[query].T_world_sensor);
}

// Query 6's pose estimate is off by 10 deg of yaw and (3, 4, 0) m in the query frame.
core::Transform OffPose() { return TrueMatchQuery(1, 6) * PoseDeg(3, 4, 0, 10); }

std::vector<QueryCandidates> LineCandidates() {
    return {
        {0, {}},
        {3, {Candidate(0, true, 0.5, TrueMatchQuery(0, 3))}},       // false loop, not revisiting
        {4, {Candidate(1, false, 0.9), Candidate(0, false, 0.1)}},  // nothing accepted
        {5, {Candidate(1, false, 0.9), Candidate(2, true, 0.8, TrueMatchQuery(2, 5))}},
        {6, {Candidate(1, true, 0.95, OffPose())}},
        // The first accepted candidate is the loop, not the best scored nor a right one.
        {7, {Candidate(3, true, 0.8), Candidate(0, true, 0.99)}},
        // 1 and 2 are not given.
    };
}

std::string ErrorOf(const std::vector<QueryCandidates>& queries, const GroundTruth& truth,
                    const std::vector<core::StampedPose>& poses) {
    try {
        EvaluateLoopRetrieval(queries, truth, poses);
    } catch (const core::Error& e) {
        return e.what();
    }
    return "no core::Error";
}

TEST(LoopRetrieval, RevisitingCountsEarlierPartnersOnly) {
    const GroundTruth truth = LineTruth();
    for (std::size_t i = 0; i < 8; ++i) {
        EXPECT_EQ(Revisiting(truth, i), i >= 5) << i;
        EXPECT_EQ(truth.Overlapping(i), i != 3 && i != 4) << i;
    }
    EXPECT_THROW(Revisiting(truth, 8), core::Error);
}

TEST(LoopRetrieval, RevisitingHonoursAGapInSeconds) {
    // Scan 2 is back at scan 0's place after 1 s: a revisit only when the gap is below 1 s.
    std::vector<core::StampedPose> poses{test::MakePose(0.0, 0, 0), test::MakePose(0.5, 50, 0),
                                         test::MakePose(1.0, 1, 0)};
    GroundTruthConfig config;
    config.distance_m = 5.0;
    config.min_gap = {0.9, core::MinGap::Unit::kSeconds};
    EXPECT_TRUE(Revisiting(BuildGroundTruth(poses, config), 2));
    config.min_gap.value = 1.0;
    EXPECT_FALSE(Revisiting(BuildGroundTruth(poses, config), 2));
}

TEST(LoopRetrieval, HandMadeSequence) {
    const auto poses = LinePoses();
    const auto queries = LineCandidates();
    const LoopRetrievalEvaluation e = EvaluateLoopRetrieval(queries, LineTruth(), poses);
    EXPECT_EQ(e.scans, 8u);
    EXPECT_EQ(e.queries, 6u);
    EXPECT_EQ(e.revisiting, 3u);  // 5, 6, 7
    EXPECT_EQ(e.k, 2u);           // the longest list
    EXPECT_EQ(e.hits_at_1, 1u);   // 6
    EXPECT_EQ(e.hits_at_k, 3u);   // 5 and 7 at rank 1
    EXPECT_DOUBLE_EQ(e.recall_at_1, 1.0 / 3.0);
    EXPECT_DOUBLE_EQ(e.recall_at_k, 1.0);

    ASSERT_EQ(e.loops.size(), 4u);  // 3, 5, 6, 7, query ascending
    const std::size_t query[] = {3, 5, 6, 7}, match[] = {0, 2, 1, 3}, rank[] = {0, 1, 0, 0};
    const bool correct[] = {false, true, true, false};
    const bool with_pose[] = {true, true, true, false}, wrong_pose[] = {false, false, true, false};
    for (std::size_t k = 0; k < 4; ++k) {
        EXPECT_EQ(e.loops[k].query, query[k]);
        EXPECT_EQ(e.loops[k].match, match[k]);
        EXPECT_EQ(e.loops[k].rank, rank[k]);
        EXPECT_EQ(e.loops[k].correct, correct[k]);
        EXPECT_EQ(e.loops[k].pose_error.has_value(), with_pose[k]);
        EXPECT_EQ(e.loops[k].wrong_pose, wrong_pose[k]) << k;
    }
    // 3 is another place seen at its true relative pose: a sound constraint, not a wrong pose.
    EXPECT_EQ(e.loops_with_pose, 3u);
    EXPECT_EQ(e.wrong_pose_loops, 1u);
    EXPECT_EQ(e.true_loops, 2u);
    EXPECT_EQ(e.false_loops, 2u);
    EXPECT_DOUBLE_EQ(e.precision, 0.5);
    EXPECT_DOUBLE_EQ(e.recall, 2.0 / 3.0);

    // By score: 0.95 (6, true), then 0.8 holds 5 (true) and 7 (false): the tie stops it.
    EXPECT_EQ(e.full_precision.true_loops, 1u);
    EXPECT_DOUBLE_EQ(e.full_precision.recall, 1.0 / 3.0);
    EXPECT_EQ(e.full_precision.min_score, 0.95);
    EXPECT_EQ(e.full_precision.first_false_score, 0.8);

    // 5 exact, 6 off by 5 m (planar) and 10 deg of yaw.
    ASSERT_EQ(e.pose_error.count, 2u);
    EXPECT_NEAR(e.pose_error.translation_m->median, 2.5, 1e-9);
    EXPECT_NEAR(e.pose_error.translation_m->max, 5.0, 1e-9);
    EXPECT_NEAR(e.pose_error.planar_m->max, 5.0, 1e-9);
    EXPECT_NEAR(e.pose_error.yaw_deg->median, 5.0, 1e-9);
    EXPECT_NEAR(e.pose_error.yaw_deg->max, 10.0, 1e-9);
    EXPECT_NEAR(e.pose_error.rotation_deg->max, 10.0, 1e-9);
    EXPECT_NEAR(e.pose_error.rotation_deg->min, 0.0, 1e-9);
}

TEST(LoopRetrieval, WrongPoseToleranceIsTheConfigs) {
    LoopRetrievalConfig config;
    config.wrong_pose_m = 5.5;  // 6 is off by 5 m and 10 deg
    EXPECT_EQ(
        EvaluateLoopRetrieval(LineCandidates(), LineTruth(), LinePoses(), config).wrong_pose_loops,
        1u);
    config.wrong_pose_deg = 10.5;
    EXPECT_EQ(
        EvaluateLoopRetrieval(LineCandidates(), LineTruth(), LinePoses(), config).wrong_pose_loops,
        0u);
    for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
        config.wrong_pose_m = bad;
        EXPECT_THROW(EvaluateLoopRetrieval(LineCandidates(), LineTruth(), LinePoses(), config),
                     core::ConfigError);
    }
}

TEST(LoopRetrieval, ExplicitKAndAFalseLoopBelowTheTie) {
    auto queries = LineCandidates();
    queries[5].ranked[0].score = 0.7;  // 7's false loop now below 5's true one
    LoopRetrievalConfig config;
    config.recall_k = 1;
    const auto e = EvaluateLoopRetrieval(queries, LineTruth(), LinePoses(), config);
    EXPECT_EQ(e.k, 1u);
    EXPECT_EQ(e.hits_at_k, 1u);
    EXPECT_EQ(e.full_precision.true_loops, 2u);
    EXPECT_DOUBLE_EQ(e.full_precision.recall, 2.0 / 3.0);
    EXPECT_EQ(e.full_precision.min_score, 0.8);
    EXPECT_EQ(e.full_precision.first_false_score, 0.7);

    config.recall_k = 10;  // longer than every list: the whole list
    EXPECT_EQ(EvaluateLoopRetrieval(queries, LineTruth(), LinePoses(), config).hits_at_k, 3u);
}

TEST(LoopRetrieval, InfiniteScoresRankAtTheEnds) {
    auto queries = LineCandidates();
    queries[1].ranked[0].score = -kInf;  // 3's false loop: never above anything
    queries[5].ranked[0].score = -kInf;  // 7's false loop too
    queries[3].ranked[1].score = kInf;   // 5's true loop first
    const auto e = EvaluateLoopRetrieval(queries, LineTruth(), LinePoses());
    EXPECT_EQ(e.full_precision.true_loops, 2u);
    EXPECT_EQ(e.full_precision.min_score, 0.95);
    EXPECT_EQ(e.full_precision.first_false_score, -kInf);
}

TEST(LoopRetrieval, PoseErrorOfKnownTransforms) {
    const core::Transform T_true = PoseDeg(10, -2, 0.5, 30);
    const RelativePoseError exact = PoseError(T_true, T_true);
    EXPECT_NEAR(exact.translation_m, 0.0, 1e-12);
    EXPECT_NEAR(exact.rotation_deg, 0.0, 1e-12);

    const RelativePoseError yaw = PoseError(T_true * PoseDeg(0, 0, 0, 10), T_true);
    EXPECT_NEAR(yaw.yaw_deg, 10.0, 1e-9);
    EXPECT_NEAR(yaw.rotation_deg, 10.0, 1e-9);
    EXPECT_NEAR(yaw.translation_m, 0.0, 1e-9);
    EXPECT_NEAR(PoseError(T_true * PoseDeg(0, 0, 0, -170), T_true).yaw_deg, 170.0, 1e-9);
    const RelativePoseError half_turn = PoseError(T_true * PoseDeg(0, 0, 0, 180), T_true);
    EXPECT_NEAR(half_turn.yaw_deg, 180.0, 1e-9);
    EXPECT_NEAR(half_turn.rotation_deg, 180.0, 1e-9);

    // Tiny angles keep their precision (acos of the trace would give 0 here).
    EXPECT_NEAR(PoseError(T_true * PoseDeg(0, 0, 0, 1e-6), T_true).rotation_deg, 1e-6, 1e-12);

    const RelativePoseError shift = PoseError(T_true * PoseDeg(3, 4, 12, 0), T_true);
    EXPECT_NEAR(shift.translation_m, 13.0, 1e-9);
    EXPECT_NEAR(shift.planar_m, 5.0, 1e-9);
    EXPECT_NEAR(shift.yaw_deg, 0.0, 1e-9);

    // Yaw 10 deg then pitch 5 deg: yaw error 10, rotation angle from the trace of Rz Ry.
    const RelativePoseError both = PoseError(T_true * PoseDeg(0, 0, 0, 10, 5), T_true);
    const double ca = std::cos(10 * kDeg), cb = std::cos(5 * kDeg);
    EXPECT_NEAR(both.yaw_deg, 10.0, 1e-9);
    EXPECT_NEAR(both.rotation_deg, std::acos((ca * cb + ca + cb - 1) / 2) / kDeg, 1e-6);
    EXPECT_NEAR(PoseError(T_true * PoseDeg(0, 0, 0, 0, 5), T_true).yaw_deg, 0.0, 1e-9);
}

TEST(LoopRetrieval, PoseErrorIsInTheQueryFrame) {
    // The query sensor is pitched 90 deg against the match sensor; the estimate is 1 m off
    // along the query's z axis, which is horizontal in the match frame: no planar error.
    const core::Transform T_true = PoseDeg(5, 0, 0, 0, 90);
    const RelativePoseError error = PoseError(T_true * PoseDeg(0, 0, 1, 0), T_true);
    EXPECT_NEAR(error.translation_m, 1.0, 1e-9);
    EXPECT_NEAR(error.planar_m, 0.0, 1e-9);
}

TEST(LoopRetrieval, TrueRelativePoseMapsQueryPointsIntoTheMatchFrame) {
    const core::Transform T_world_match = PoseDeg(10, 0, 0, 90);
    const core::Transform T_world_query = PoseDeg(10, 5, 0, 180);
    const core::Transform T_match_query = TrueRelativePose(T_world_match, T_world_query);
    // The query's origin is 5 m along the match's x axis (which points along world y).
    EXPECT_TRUE(T_match_query.translation().isApprox(Eigen::Vector3d(5, 0, 0), 1e-12));
    const Eigen::Vector3d p_query(1, 2, 3);
    EXPECT_TRUE((T_world_match * (T_match_query * p_query)).isApprox(T_world_query * p_query));
}

TEST(LoopRetrieval, NoAcceptedLoops) {
    auto queries = LineCandidates();
    for (auto& q : queries) {
        for (auto& c : q.ranked) c.accepted = false;
    }
    const auto e = EvaluateLoopRetrieval(queries, LineTruth(), LinePoses());
    EXPECT_EQ(e.hits_at_k, 3u);  // retrieval ignores the decisions
    EXPECT_TRUE(e.loops.empty());
    EXPECT_EQ(e.true_loops + e.false_loops, 0u);
    EXPECT_TRUE(std::isnan(e.precision));
    EXPECT_EQ(e.recall, 0.0);
    EXPECT_EQ(e.full_precision.recall, 0.0);
    EXPECT_EQ(e.full_precision.min_score, kInf);
    EXPECT_EQ(e.full_precision.first_false_score, -kInf);
    EXPECT_EQ(e.pose_error.count, 0u);
    EXPECT_FALSE(e.pose_error.translation_m.has_value());
    EXPECT_FALSE(e.pose_error.rotation_deg.has_value());
}

TEST(LoopRetrieval, NoRevisitingScans) {
    // Scans 5..7 moved far away: nothing is revisited, every accepted loop is false.
    auto poses = LinePoses();
    for (std::size_t i = 5; i < 8; ++i) poses[i].T_world_sensor.translation().y() = 500.0;
    GroundTruthConfig config;
    config.distance_m = 5.0;
    config.min_gap = {2.0, core::MinGap::Unit::kScans};
    const auto e = EvaluateLoopRetrieval(LineCandidates(), BuildGroundTruth(poses, config), poses);
    EXPECT_EQ(e.revisiting, 0u);
    EXPECT_EQ(e.hits_at_1 + e.hits_at_k, 0u);
    EXPECT_TRUE(std::isnan(e.recall_at_1));
    EXPECT_TRUE(std::isnan(e.recall_at_k));
    EXPECT_TRUE(std::isnan(e.recall));
    EXPECT_EQ(e.true_loops, 0u);
    EXPECT_EQ(e.false_loops, 4u);
    EXPECT_EQ(e.precision, 0.0);
    EXPECT_TRUE(std::isnan(e.full_precision.recall));
    EXPECT_EQ(e.full_precision.true_loops, 0u);
    EXPECT_EQ(e.full_precision.min_score, kInf);
    EXPECT_EQ(e.full_precision.first_false_score, 0.95);
    EXPECT_EQ(e.pose_error.count, 0u);  // poses of false loops are not scored
}

// A gap in metres is the detector's: measured on its odometry's path, which may be longer than
// the truth's. Its candidates are checked against that path; revisits still by the truth.
TEST(LoopRetrieval, AGapInMetresIsCheckedOnTheDetectorsPath) {
    GroundTruthConfig config;
    config.distance_m = 5.0;
    config.min_gap = {50.0, core::MinGap::Unit::kMetres};
    const auto poses = LinePoses();
    const GroundTruth truth = BuildGroundTruth(poses, config);  // path 0 20 40 60 80 118 139 159
    std::vector<double> odometry_path_m = truth.path_m;
    for (double& path_m : odometry_path_m) path_m *= 2.0;
    // Scan 4 is 38 m of true path before 5 but 76 m of the odometry's: a candidate of the
    // detector, and the wrong place (38 m away).
    const std::vector<QueryCandidates> queries = {
        {5, {Candidate(4, true, 0.9), Candidate(2, true, 0.8, TrueMatchQuery(2, 5))}}};
    EXPECT_TRUE(test::Contains(ErrorOf(queries, truth, poses), "outside the minimum gap"));
    const auto e = EvaluateLoopRetrieval(queries, truth, poses, {}, odometry_path_m);
    EXPECT_EQ(e.revisiting, 3u);
    EXPECT_EQ(e.hits_at_1, 0u);
    EXPECT_EQ(e.hits_at_k, 1u);
    EXPECT_EQ(e.false_loops, 1u);
    EXPECT_EQ(e.true_loops, 0u);

    // A candidate within the detector's own gap is still an error, and so is a path that does
    // not fit the truth.
    odometry_path_m[4] = odometry_path_m[5] - 10.0;
    EXPECT_THROW(EvaluateLoopRetrieval(queries, truth, poses, {}, odometry_path_m), core::Error);
    odometry_path_m.pop_back();
    try {
        EvaluateLoopRetrieval(queries, truth, poses, {}, odometry_path_m);
        ADD_FAILURE() << "no error";
    } catch (const core::Error& error) {
        EXPECT_TRUE(test::Contains(error.what(), "the detector's path has 7 scans"))
            << error.what();
    }
}

TEST(LoopRetrieval, EmptyInput) {
    const auto e = EvaluateLoopRetrieval({}, LineTruth(), LinePoses());
    EXPECT_EQ(e.queries, 0u);
    EXPECT_EQ(e.k, 0u);
    EXPECT_EQ(e.revisiting, 3u);  // not given = no candidates: all missed
    EXPECT_EQ(e.recall_at_1, 0.0);
    EXPECT_EQ(e.recall_at_k, 0.0);
    EXPECT_EQ(e.recall, 0.0);
    EXPECT_TRUE(std::isnan(e.precision));

    const auto none = EvaluateLoopRetrieval({}, BuildGroundTruth({}, {}), {});
    EXPECT_EQ(none.scans, 0u);
    EXPECT_TRUE(std::isnan(none.recall_at_1));
    EXPECT_TRUE(std::isnan(none.full_precision.recall));
}

TEST(LoopRetrieval, BadInputThrowsNamingTheQueryAndCandidate) {
    const GroundTruth truth = LineTruth();
    const auto poses = LinePoses();
    const auto with = [](auto change) {
        auto queries = LineCandidates();
        change(queries);
        return queries;
    };
    EXPECT_TRUE(test::Contains(ErrorOf(LineCandidates(), truth, {}), "0 poses for"));
    EXPECT_TRUE(test::Contains(ErrorOf(with([](auto& q) { q[0].query = 8; }), truth, poses),
                               "query 8 is out of range"));
    EXPECT_TRUE(test::Contains(ErrorOf(with([](auto& q) { q[0].query = 6; }), truth, poses),
                               "query 6 is given twice"));
    const auto candidate_error = [&](std::size_t match) {
        return ErrorOf(with([&](auto& q) { q[4].ranked.push_back(Candidate(match, false, 0)); }),
                       truth, poses);
    };
    for (const std::size_t match : {4u, 5u, 6u, 7u, 99u}) {  // within the gap, later, itself
        EXPECT_TRUE(test::Contains(candidate_error(match),
                                   "query 6, candidate 1 (scan " + std::to_string(match) +
                                       ") is not an earlier scan outside the minimum gap"));
    }
    EXPECT_TRUE(test::Contains(
        ErrorOf(with([](auto& q) { q[1].ranked.push_back(Candidate(7, false, 0)); }), truth, poses),
        "query 3, candidate 1 (scan 7) is not an earlier scan"));  // later, outside the gap
    EXPECT_TRUE(test::Contains(candidate_error(1), "query 6: scan 1 is a candidate twice"));
    EXPECT_EQ(candidate_error(3), "no core::Error");
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_TRUE(
        test::Contains(ErrorOf(with([&](auto& q) { q[3].ranked[0].score = nan; }), truth, poses),
                       "query 5, candidate 0 (scan 1): score is NaN"));
    EXPECT_TRUE(
        test::Contains(ErrorOf(with([&](auto& q) { q[3].ranked[0].distance = nan; }), truth, poses),
                       "query 5, candidate 0 (scan 1): distance is NaN"));
    EXPECT_TRUE(test::Contains(
        ErrorOf(with([&](auto& q) { q[4].ranked[0].T_match_query->translation().x() = nan; }),
                truth, poses),
        "query 6, candidate 0 (scan 1): T_match_query is not finite"));
    EXPECT_TRUE(test::Contains(
        ErrorOf(with([&](auto& q) { q[4].ranked[0].T_match_query->linear() *= 1.01; }), truth,
                poses),
        "query 6, candidate 0 (scan 1): the linear part of T_match_query is not a rotation"));
    EXPECT_TRUE(test::Contains(
        ErrorOf(with([&](auto& q) { q[4].ranked[0].T_match_query->linear().col(2) *= -1.0; }),
                truth, poses),
        "is not a rotation"));  // a reflection
}

// ---- brute-force cross-check on random input ----

struct Reference {
    std::size_t revisiting = 0, hits_at_1 = 0, hits_at_k = 0, true_loops = 0, false_loops = 0;
    std::size_t full_precision_true = 0;
    double min_score = kInf;
    double first_false_score = -kInf;
};

// Straight from the definitions: positions and the gap, no GroundTruth queries.
bool SamePlace(const std::vector<core::StampedPose>& poses, std::size_t i, std::size_t j,
               double distance_m) {
    return (poses[i].T_world_sensor.translation() - poses[j].T_world_sensor.translation()).norm() <
           distance_m;
}

Reference BruteForce(const std::vector<QueryCandidates>& queries,
                     const std::vector<core::StampedPose>& poses, double distance_m,
                     std::size_t gap, std::size_t k) {
    Reference ref;
    for (std::size_t i = 0; i < poses.size(); ++i) {
        bool revisiting = false;
        for (std::size_t j = 0; j + gap < i; ++j) revisiting |= SamePlace(poses, i, j, distance_m);
        ref.revisiting += revisiting;
    }
    struct Loop {
        double score;
        bool correct;
    };
    std::vector<Loop> loops;
    for (const auto& q : queries) {
        for (std::size_t r = 0; r < q.ranked.size(); ++r) {
            if (!SamePlace(poses, q.query, q.ranked[r].match, distance_m)) continue;
            ref.hits_at_1 += r == 0;
            ref.hits_at_k += r < k;
            break;
        }
        for (const auto& c : q.ranked) {
            if (!c.accepted) continue;
            loops.push_back({c.score, SamePlace(poses, q.query, c.match, distance_m)});
            (loops.back().correct ? ref.true_loops : ref.false_loops)++;
            if (!loops.back().correct) {
                ref.first_false_score = std::max(ref.first_false_score, c.score);
            }
            break;
        }
    }
    // Every threshold t among the scores: keep the loops with score >= t; valid when none of
    // them is false. O(n^2).
    for (const Loop& candidate : loops) {
        std::size_t kept_true = 0;
        bool any_false = false;
        for (const Loop& loop : loops) {
            if (loop.score < candidate.score) continue;
            kept_true += loop.correct;
            any_false = any_false || !loop.correct;
        }
        if (!any_false && kept_true > ref.full_precision_true) {
            ref.full_precision_true = kept_true;
            ref.min_score = candidate.score;
        }
    }
    return ref;
}

std::vector<QueryCandidates> RandomCandidates(const std::vector<core::StampedPose>& poses,
                                              std::size_t gap, double distance_m,
                                              std::mt19937& rng) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<QueryCandidates> queries;
    for (std::size_t i = gap + 1; i < poses.size(); ++i) {
        if (unit(rng) < 0.1) continue;  // not given
        std::vector<std::size_t> pool, near;
        for (std::size_t j = 0; j + gap < i; ++j) {
            pool.push_back(j);
            if (SamePlace(poses, i, j, distance_m)) near.push_back(j);
        }
        std::shuffle(pool.begin(), pool.end(), rng);
        pool.resize(std::min<std::size_t>(pool.size(), 1 + rng() % 5));
        // Often put a true partner somewhere in the list.
        if (!near.empty() && unit(rng) < 0.7) {
            const std::size_t partner = near[rng() % near.size()];
            if (std::find(pool.begin(), pool.end(), partner) == pool.end()) {
                pool[rng() % pool.size()] = partner;
            }
        }
        QueryCandidates q{i, {}};
        for (const std::size_t j : pool) {
            // Few distinct scores, so ties are common; true loops score higher and are accepted
            // more often, as by a useful pipeline; some scores are infinite.
            const bool same_place = SamePlace(poses, i, j, distance_m);
            double score = (same_place ? 4.0 : 0.0) + static_cast<double>(rng() % 6);
            if (unit(rng) < 0.01) score = unit(rng) < 0.5 ? kInf : -kInf;
            q.ranked.push_back(Candidate(j, unit(rng) < (same_place ? 0.7 : 0.1), score));
        }
        queries.push_back(std::move(q));
    }
    std::shuffle(queries.begin(), queries.end(), rng);  // any query order
    return queries;
}

TEST(LoopRetrieval, MatchesBruteForceOnRandomInput) {
    constexpr std::size_t kGap = 30;
    constexpr double kDistance = 10.0;
    GroundTruthConfig config;
    config.distance_m = kDistance;
    config.min_gap = {static_cast<double>(kGap), core::MinGap::Unit::kScans};
    std::size_t nontrivial = 0;
    for (unsigned seed = 1; seed <= 30; ++seed) {
        const auto poses = test::RandomTrajectory(seed, 250);
        const GroundTruth truth = BuildGroundTruth(poses, config);
        std::mt19937 rng(seed);
        const auto queries = RandomCandidates(poses, kGap, kDistance, rng);
        LoopRetrievalConfig retrieval;
        retrieval.recall_k = 1 + seed % 4;
        const auto e = EvaluateLoopRetrieval(queries, truth, poses, retrieval);
        const Reference ref = BruteForce(queries, poses, kDistance, kGap, retrieval.recall_k);
        SCOPED_TRACE(seed);
        EXPECT_EQ(e.revisiting, ref.revisiting);
        EXPECT_EQ(e.hits_at_1, ref.hits_at_1);
        EXPECT_EQ(e.hits_at_k, ref.hits_at_k);
        EXPECT_EQ(e.true_loops, ref.true_loops);
        EXPECT_EQ(e.false_loops, ref.false_loops);
        EXPECT_EQ(e.full_precision.true_loops, ref.full_precision_true);
        EXPECT_EQ(e.full_precision.min_score, ref.min_score);
        EXPECT_EQ(e.full_precision.first_false_score, ref.first_false_score);
        EXPECT_EQ(e.loops.size(), ref.true_loops + ref.false_loops);
        EXPECT_TRUE(
            std::is_sorted(e.loops.begin(), e.loops.end(), [](const auto& a, const auto& b) {
                return a.query < b.query;
            }));  // the queries come shuffled
        if (ref.revisiting == 0) {
            EXPECT_TRUE(std::isnan(e.full_precision.recall));
            continue;
        }
        const auto share = [&](std::size_t count) {
            return static_cast<double>(count) / static_cast<double>(ref.revisiting);
        };
        EXPECT_DOUBLE_EQ(e.full_precision.recall, share(ref.full_precision_true));
        EXPECT_DOUBLE_EQ(e.recall, share(ref.true_loops));
        EXPECT_DOUBLE_EQ(e.recall_at_k, share(ref.hits_at_k));
        // Metric bounds.
        EXPECT_LE(e.full_precision.recall, e.recall);
        EXPECT_LE(e.recall_at_1, e.recall_at_k);
        EXPECT_LE(e.full_precision.first_false_score, e.full_precision.min_score);
        nontrivial += ref.full_precision_true > 0 && ref.full_precision_true < ref.true_loops;
    }
    EXPECT_GE(nontrivial, 10u);  // the random cases do exercise the search
}

}  // namespace
}  // namespace lidarloop::eval

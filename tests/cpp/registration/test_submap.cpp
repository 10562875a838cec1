#include "lidarloop/registration/submap.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/registration/coarse_alignment.hpp"
#include "lidarloop/registration/icp.hpp"
#include "lidarloop/registration/verification.hpp"
#include "lidarloop/sim/simulator.hpp"
#include "sparse_keyframes.hpp"

namespace lidarloop::registration {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

core::StampedPose PoseAt(double x, double yaw_rad) {
    core::StampedPose pose;
    pose.T_world_sensor.translate(Eigen::Vector3d(x, 0.5 * x, 0.1));
    pose.T_world_sensor.rotate(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()));
    return pose;
}

// Scans 1 m apart along a line: path positions 0, 1, 2, ... (scaled by sqrt(1.25) in x, y).
std::vector<core::StampedPose> LinePoses(std::size_t count) {
    std::vector<core::StampedPose> poses;
    for (std::size_t i = 0; i < count; ++i)
        poses.push_back(
            PoseAt(static_cast<double>(i) / std::sqrt(1.25), 0.1 * static_cast<double>(i)));
    return poses;
}

core::PointCloud RandomScan(std::mt19937& random, std::size_t count) {
    std::uniform_real_distribution<float> coordinate(-30.0F, 30.0F);
    core::PointCloud scan;
    for (std::size_t i = 0; i < count; ++i)
        scan.push_back({coordinate(random), coordinate(random), 0.1F * coordinate(random)});
    scan.emplace_back(1.0F, 0.0F, 0.0F);  // inside min_range: the scan's own vehicle
    scan.emplace_back(kNaN, 0.0F, 0.0F);
    return scan;
}

TEST(Submap, MembersAreTheScansWithinThePathWindow) {
    const std::vector<double> path_m = SubmapPathM(LinePoses(10));
    EXPECT_NEAR(path_m[9], 9.0, 1e-9);
    EXPECT_EQ(SubmapMembers(path_m, 5, {2.5, 10, false}),
              (std::vector<std::size_t>{3, 4, 5, 6, 7}));
    EXPECT_EQ(SubmapMembers(path_m, 5, {2.5, 1, false}), (std::vector<std::size_t>{4, 5, 6}));
    EXPECT_EQ(SubmapMembers(path_m, 5, {2.5, 10, true}), (std::vector<std::size_t>{3, 4, 5}));
    EXPECT_EQ(SubmapMembers(path_m, 5, {0.0, 10, false}), (std::vector<std::size_t>{5}));
}

TEST(Submap, FewerNeighboursAtTheSequenceEnds) {
    const std::vector<double> path_m = SubmapPathM(LinePoses(10));
    EXPECT_EQ(SubmapMembers(path_m, 0, {2.5, 10, false}), (std::vector<std::size_t>{0, 1, 2}));
    EXPECT_EQ(SubmapMembers(path_m, 9, {2.5, 10, false}), (std::vector<std::size_t>{7, 8, 9}));
    EXPECT_EQ(SubmapMembers({0.0}, 0, {2.5, 10, false}), (std::vector<std::size_t>{0}));
}

TEST(Submap, ScansWithoutAFinitePoseJoinNoSubmap) {
    std::vector<core::StampedPose> poses = LinePoses(10);
    poses[4].T_world_sensor.translation().x() = kNaN;
    poses[6].T_world_sensor.linear()(0, 0) = kNaN;
    const std::vector<double> path_m = SubmapPathM(poses);
    EXPECT_TRUE(std::isnan(path_m[4]));
    EXPECT_TRUE(std::isnan(path_m[6]));
    EXPECT_NEAR(path_m[5], 5.0, 1e-9);  // the path continues over the gap
    EXPECT_EQ(SubmapMembers(path_m, 5, {2.5, 10, false}), (std::vector<std::size_t>{3, 5, 7}));
    EXPECT_EQ(SubmapMembers(path_m, 4, {2.5, 10, false}), (std::vector<std::size_t>{4}));
}

// Frames of a longer drive: two visits of one place 3 m apart in a straight line, 600 m of path
// apart, must not share a submap.
TEST(Submap, FramesOfALongerDriveAreApartByItsPath) {
    std::vector<core::StampedPose> poses = {PoseAt(0.0, 0.0), PoseAt(1.0, 0.0), PoseAt(3.0, 0.0)};
    poses[0].path_m = 100.0;
    poses[1].path_m = 101.0;
    poses[2].path_m = 701.0;
    const std::vector<double> path_m = SubmapPathM(poses);
    EXPECT_EQ(path_m, (std::vector<double>{0.0, 1.0, 601.0}));
    EXPECT_EQ(SubmapMembers(path_m, 1, {5.0, 10, false}), (std::vector<std::size_t>{0, 1}));
    poses[1].path_m.reset();  // not every pose knows it: the straight steps
    EXPECT_EQ(SubmapMembers(SubmapPathM(poses), 1, {5.0, 10, false}),
              (std::vector<std::size_t>{0, 1, 2}));
}

// The merge against a brute-force one: every usable point of every scan, by its own sensor's
// range, moved by inverse(T_world_centre) * T_world_scan.
TEST(Submap, MergeIsEveryUsablePointInTheCentreFrame) {
    std::mt19937 random(7);
    const std::vector<core::StampedPose> poses = LinePoses(3);
    const std::vector<core::PointCloud> scans{RandomScan(random, 500), RandomScan(random, 400),
                                              RandomScan(random, 300)};
    const ScanReductionConfig config;
    std::vector<core::Transform> T_world_scans;
    for (const auto& pose : poses) T_world_scans.push_back(pose.T_world_sensor);
    const core::PointCloud merged = MergeIntoFrame(scans, T_world_scans, T_world_scans[1], config);
    core::PointCloud expected;
    for (std::size_t s = 0; s < scans.size(); ++s) {
        const core::Transform T = T_world_scans[1].inverse() * T_world_scans[s];
        for (const Eigen::Vector3f& p : scans[s]) {
            const double range_m = p.cast<double>().norm();
            if (!p.allFinite() || range_m < config.min_range_m || range_m > config.max_range_m)
                continue;
            expected.push_back((T * p.cast<double>()).cast<float>());
        }
    }
    ASSERT_EQ(merged.size(), expected.size());
    for (std::size_t i = 0; i < merged.size(); ++i)
        EXPECT_LT((merged[i] - expected[i]).norm(), 1e-4F) << i;
}

TEST(Submap, PrepareSubmapIsPrepareScanOfTheMerge) {
    std::mt19937 random(11);
    const std::vector<core::StampedPose> poses = LinePoses(5);
    std::vector<core::PointCloud> scans;
    for (int i = 0; i < 5; ++i) scans.push_back(RandomScan(random, 2000));
    ScanReductionConfig config;
    config.submap_path_m = 1.5;
    const auto load = [&scans](std::size_t k) { return scans.at(k); };
    const PreparedScan submap = PrepareSubmap(2, poses, SubmapPathM(poses), load, config);
    std::vector<core::Transform> T_world_scans;
    for (int k = 1; k <= 3; ++k) T_world_scans.push_back(poses[k].T_world_sensor);
    const PreparedScan expected =
        PrepareScan(MergeIntoFrame({scans[1], scans[2], scans[3]}, T_world_scans,
                                   poses[2].T_world_sensor, config),
                    config);
    ASSERT_EQ(submap.structure->size(), expected.structure->size());
    EXPECT_EQ(submap.structure->points(), expected.structure->points());
    EXPECT_EQ(submap.ground->points(), expected.ground->points());
    EXPECT_GT(submap.usable_points, PrepareScan(scans[2], config).usable_points);
    // It looks where its centre scan looks, not where its neighbours do.
    EXPECT_EQ(submap.view_centre, PrepareScan(scans[2], config).view_centre);
    EXPECT_FALSE(submap.view_centre.isApprox(expected.view_centre, 1e-3));
}

// Dense scans fill a submap with few neighbours: the point budget keeps the centre, then its
// nearest neighbours in path (the earlier of two equally near) until one does not fit; no
// farther scan fills the gap (the submap stays one stretch of road).
TEST(Submap, ThePointBudgetKeepsTheNearestNeighbours) {
    std::mt19937 random(12);
    const std::vector<core::StampedPose> poses = LinePoses(7);
    const std::vector<double> path_m = {0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0};  // exact ties
    std::vector<core::PointCloud> scans;
    for (int i = 0; i < 7; ++i) scans.push_back(RandomScan(random, i == 1 ? 30'000 : 10'000));
    const auto scan_points = static_cast<int>(scans[0].size());  // with the unusable two
    ScanReductionConfig config;
    config.submap_path_m = 10.0;  // every scan within the window
    const auto load = [&scans](std::size_t k) { return scans.at(k); };
    const auto structure_of = [&](std::initializer_list<std::size_t> members) {
        std::vector<core::PointCloud> chosen;
        std::vector<core::Transform> T_world_scans;
        for (const std::size_t k : members) {
            chosen.push_back(scans[k]);
            T_world_scans.push_back(poses[k].T_world_sensor);
        }
        return PrepareScan(MergeIntoFrame(chosen, T_world_scans, poses[3].T_world_sensor, config),
                           config)
            .structure->points();
    };
    const auto submap_structure = [&](int max_points) {
        config.submap_max_points = max_points;
        return PrepareSubmap(3, poses, path_m, load, config).structure->points();
    };
    // Room for four scans: 3, 2 and 4; then scan 1 (three scans' points) does not fit, and 5,
    // as near, is not taken in its place.
    EXPECT_EQ(submap_structure(4 * scan_points), structure_of({2, 3, 4}));
    // Room for two: of 2 and 4, equally near, the earlier.
    EXPECT_EQ(submap_structure(2 * scan_points), structure_of({2, 3}));
    // Less than the centre's own points: the centre alone still.
    EXPECT_EQ(submap_structure(10'000), PrepareScan(scans[3], config).structure->points());
    // Room for all: the whole window.
    EXPECT_EQ(submap_structure(100'000'000), structure_of({0, 1, 2, 3, 4, 5, 6}));
}

TEST(Submap, WithoutAPoseTheScanIsPreparedAlone) {
    std::mt19937 random(3);
    std::vector<core::StampedPose> poses = LinePoses(3);
    const std::vector<core::PointCloud> scans{RandomScan(random, 800), RandomScan(random, 800),
                                              RandomScan(random, 800)};
    const auto load = [&scans](std::size_t k) { return scans.at(k); };
    poses[1].T_world_sensor.translation().z() = kNaN;
    const ScanReductionConfig config;
    const PreparedScan alone = PrepareSubmap(1, poses, SubmapPathM(poses), load, config);
    EXPECT_EQ(alone.structure->points(), PrepareScan(scans[1], config).structure->points());
    // The window off: the scan alone too.
    ScanReductionConfig off = config;
    off.submap_path_m = 0.0;
    const std::vector<core::StampedPose> good = LinePoses(3);
    EXPECT_EQ(PrepareSubmap(1, good, SubmapPathM(good), load, off).structure->points(),
              PrepareScan(scans[1], config).structure->points());
    // NaN everywhere else: nothing joins.
    EXPECT_NO_THROW(PrepareSubmap(0, poses, SubmapPathM(poses), load, config));
}

TEST(Submap, ConfigRangesAreValidated) {
    ScanReductionConfig config;
    config.submap_path_m = -1.0;
    EXPECT_THROW(config.Validate(), core::ConfigError);
    config.submap_path_m = kNaN;
    EXPECT_THROW(config.Validate(), core::ConfigError);
    config = {};
    config.submap_max_scans = -1;
    EXPECT_THROW(config.Validate(), core::ConfigError);
    config = {};
    config.submap_max_points = 9'999;
    EXPECT_THROW(config.Validate(), core::ConfigError);
}

// Sparse keyframes in open country (`lidarloop simulate --scene rural --route uturn --seed 3
// (or another) --sensor hdl32 --keep-every 10 --scans 300 --spacing-min-m 1 --spacing-max-m 2`, or
// another sensor and thinning) and one of its revisits: the query and match scans, the true
// T_match_query, and both scans as submaps (the neighbours within `window_m` of path, placed by
// the drifting odometry). The pairs below were picked with 5 m windows, the default before 10 m,
// to show one mechanism each; they keep that window.
struct SparseRuralRevisit {
    SparseRuralRevisit(std::size_t query_scan, std::size_t match_scan,
                       sim::SensorModel sensor = sim::SensorModel::kHdl32,
                       std::int64_t keep_every = 10, double window_m = 5.0, std::uint64_t seed = 3)
        : simulator(test::SparseUTurnKeyframes(sim::SceneType::kRural, keep_every, sensor, seed)),
          query(query_scan),
          match(match_scan),
          truth(simulator.GroundTruthPose(match).T_world_sensor.inverse() *
                simulator.GroundTruthPose(query).T_world_sensor),
          config(WithWindow(window_m)) {
        const std::vector<core::StampedPose> odometry =
            simulator.OdometryPoses(0, simulator.size());
        const std::vector<double> path_m = SubmapPathM(odometry);
        const auto load = [this](std::size_t k) { return simulator.Scan(k); };
        query_submap = PrepareSubmap(query, odometry, path_m, load, config.reduction);
        match_submap = PrepareSubmap(match, odometry, path_m, load, config.reduction);
    }
    Verification VerifySubmaps(const PoseAllowed& allowed = {}) const {
        return VerifySubmaps(config, allowed);
    }
    Verification VerifySubmaps(const VerificationConfig& with,
                               const PoseAllowed& allowed = {}) const {
        const CoarseQuery coarse(*query_submap.structure, with.coarse);
        return Verify(query_submap, coarse, match_submap, with, allowed);
    }
    double ErrorM(const Verification& verification) const {
        return (verification.T_match_query.translation() - truth.translation()).norm();
    }
    // The odometry's gate as it would judge here: within 5 m of the true pose.
    PoseAllowed NearTheTruth() const {
        return [truth = truth](const core::Transform& T_match_query) {
            return (T_match_query.translation() - truth.translation()).norm() < 5.0;
        };
    }

    static VerificationConfig WithWindow(double window_m) {
        VerificationConfig config;
        config.reduction.submap_path_m = window_m;
        return config;
    }

    const sim::Simulator simulator;
    const std::size_t query, match;
    const core::Transform truth;
    const VerificationConfig config;
    PreparedScan query_submap, match_submap;
};

// Scan 294 revisits scan 87 in the opposite direction, 6.9 m away. One scan of 133 structure
// points overlaps the other too little to pass (low_overlap: fewer than 80 points on the other's
// surfaces); as submaps the two overlap 0.9 at the true pose (bench/verify_replay,
// docs/verification.md "Submaps").
TEST(Submap, SparseRuralRevisitNeedsTheSubmap) {
    const SparseRuralRevisit revisit(294, 87);
    const Verification alone = VerifyPair(revisit.simulator.Scan(revisit.query),
                                          revisit.simulator.Scan(revisit.match), revisit.config);
    EXPECT_FALSE(alone.accepted) << "one scan alone now suffices: pick a harder pair";
    const Verification merged = revisit.VerifySubmaps();
    EXPECT_TRUE(merged.accepted) << ToString(merged.reason);
    EXPECT_LT(revisit.ErrorM(merged), 0.3);
}

// Scan 290 back to scan 84, 8.2 m apart: as submaps the right pose is found, but the road leaves
// only a handful of points facing along it (5 to 19: fewer than the 20 asked of the geometry
// alone). Where the odometry judges the pose (its gate rejects a look-alike place farther along
// the road), 5 suffice, and the loop is accepted at the true pose (docs/verification.md, "The
// odometry pins the road").
TEST(Submap, ARoadPinnedByAFewPointsIsALoopWhereTheOdometryJudgesIt) {
    const SparseRuralRevisit revisit(290, 84);
    const Verification alone = revisit.VerifySubmaps();
    EXPECT_EQ(alone.reason, RejectReason::kDegenerate) << "pick a pair the floor rejects";
    EXPECT_LT(alone.overlap.constraining_points,
              static_cast<std::size_t>(revisit.config.acceptance.min_constraining_points));
    EXPECT_LE(alone.overlap.shifted_overlap_ratio,
              revisit.config.acceptance.max_shifted_overlap_ratio);

    const Verification judged = revisit.VerifySubmaps(revisit.NearTheTruth());
    EXPECT_TRUE(judged.accepted) << ToString(judged.reason);
    EXPECT_LT(revisit.ErrorM(judged), 0.1);
}

// Scan 170 back to scan 31, 3.5 m apart, as submaps: fewer than the odometry's floor of 5
// overlapping points face along the road within 60 degrees, but more than that many slanted ones
// leave their planes when the pose slides 2 m, so where the odometry judges the pose they pin it
// and the loop is accepted at the true pose (docs/verification.md, "Slanted surfaces pin the
// road"). Before 2026-11-28 it was rejected as degenerate.
TEST(Submap, SlantedSurfacesPinARoadWhereTheOdometryJudgesIt) {
    const SparseRuralRevisit revisit(170, 31);
    const Verification judged = revisit.VerifySubmaps(revisit.NearTheTruth());
    ASSERT_TRUE(judged.accepted) << ToString(judged.reason);
    EXPECT_LT(revisit.ErrorM(judged), 0.1);
    const AcceptanceConfig& acceptance = revisit.config.acceptance;
    const Overlap within_60_degrees = MeasureOverlap(revisit.query_submap, revisit.match_submap,
                                                     judged.T_match_query, acceptance, false);
    EXPECT_LT(within_60_degrees.constraining_points, MinConstrainingPoints(acceptance, true))
        << "pick a pair the 60 degree rule rejects";
    EXPECT_GE(judged.overlap.constraining_points, MinConstrainingPoints(acceptance, true));
    EXPECT_LE(judged.overlap.shifted_overlap_ratio, acceptance.max_shifted_overlap_ratio);
}

// Scan 135 back to scan 60, 3.9 m apart, where trees repeat along the road: a second pose 12 m
// on fits nearly as well, so the place is ambiguous. The odometry's gate rules that pose out, and
// then only the right one is left; a rival it allows still counts.
TEST(Submap, ARivalPoseTheOdometryRulesOutLeavesTheRightOne) {
    const SparseRuralRevisit revisit(135, 60);
    const PoseAllowed any_pose = [](const core::Transform& /*unused*/) { return true; };
    EXPECT_EQ(revisit.VerifySubmaps(any_pose).reason, RejectReason::kAmbiguous)
        << "pick a pair with a rival";
    const Verification judged = revisit.VerifySubmaps(revisit.NearTheTruth());
    EXPECT_TRUE(judged.accepted) << ToString(judged.reason);
    EXPECT_LT(revisit.ErrorM(judged), 0.1);
}

// Scan 292 back to scan 82, one scan each (no odometry): the right pose overlaps well (0.62 and
// 0.79) but with fewer than 80 points each way, the floor before 2026-11-28. 60 points each way
// pass (docs/BENCHMARK.md, "The overlap floor").
TEST(Submap, SixtyOverlappingPointsPinASparseRuralLoop) {
    const SparseRuralRevisit revisit(292, 82);
    const core::PointCloud query = revisit.simulator.Scan(revisit.query);
    const core::PointCloud match = revisit.simulator.Scan(revisit.match);
    const Verification alone = VerifyPair(query, match, revisit.config);
    ASSERT_TRUE(alone.accepted) << ToString(alone.reason);
    EXPECT_LT(revisit.ErrorM(alone), 0.1);
    EXPECT_LT(std::min(alone.overlap.query_overlapping, alone.overlap.match_overlapping), 80u)
        << "pick a pair the old floor rejects";
    VerificationConfig old_floor = revisit.config;
    old_floor.acceptance.min_overlapping_points = 80;
    old_floor.acceptance.overlap_confidence_z = 0.0;  // the floor alone, as before 2026-11-30
    EXPECT_EQ(VerifyPair(query, match, old_floor).reason, RejectReason::kLowOverlap);
}

// Another drive (seed 7), scan 118 back to scan 63, 3.6 m apart, as 10 m submaps: the right pose
// overlaps 0.75 each way, but the two see only about 50 structure points in common, and fewer than
// 60 overlap. Their share's lower bound at 2.5 standard errors is still over the 0.35 bar, so the
// loop is accepted at the true pose; the fixed floor of 60 points (overlap_confidence_z 0, before
// 2026-11-30) rejects it (docs/BENCHMARK.md, "Fewer points where the share is clear").
TEST(Submap, AClearShareOfFewPointsIsALoop) {
    const SparseRuralRevisit revisit(118, 63, sim::SensorModel::kHdl32, 10,
                                     ScanReductionConfig{}.submap_path_m, 7);
    const Verification judged = revisit.VerifySubmaps(revisit.NearTheTruth());
    ASSERT_TRUE(judged.accepted) << ToString(judged.reason);
    EXPECT_LT(revisit.ErrorM(judged), 0.1);
    const auto fewest = static_cast<std::size_t>(revisit.config.acceptance.min_overlapping_points);
    EXPECT_LT(std::min(judged.overlap.query_overlapping, judged.overlap.match_overlapping), fewest)
        << "pick a pair the fixed floor rejects";
    VerificationConfig fixed_floor = revisit.config;
    fixed_floor.acceptance.overlap_confidence_z = 0.0;
    EXPECT_EQ(revisit.VerifySubmaps(fixed_floor, revisit.NearTheTruth()).reason,
              RejectReason::kLowOverlap);
}

// Rural VLP-16 (every point), scan 176 back to scan 26, 3.5 m apart, as submaps: the right pose
// overlaps 0.9 but its RMSE, from tree crowns and field edges, is over the scans' own roughness.
// Where the odometry judges the pose, 1.25 x the roughness is allowed and the loop is accepted
// at the true pose; 1.0, the bar without odometry, rejects it (docs/BENCHMARK.md, "The RMSE bar
// where the odometry judges").
TEST(Submap, VegetationFitsLooselyWhereTheOdometryJudgesThePose) {
    const SparseRuralRevisit revisit(176, 26, sim::SensorModel::kVlp16, 1);
    const Verification alone = revisit.VerifySubmaps();
    EXPECT_EQ(alone.reason, RejectReason::kHighRmse) << "pick a pair the RMSE bar rejects";
    const Verification judged = revisit.VerifySubmaps(revisit.NearTheTruth());
    EXPECT_TRUE(judged.accepted) << ToString(judged.reason);
    EXPECT_LT(revisit.ErrorM(judged), 0.1);
    VerificationConfig old_bar = revisit.config;
    old_bar.acceptance.max_rmse_ratio_with_odometry = old_bar.acceptance.max_rmse_ratio;
    EXPECT_EQ(revisit.VerifySubmaps(old_bar, revisit.NearTheTruth()).reason,
              RejectReason::kHighRmse);
}

// The same pair without the odometry's judgement: with 10 m of neighbours on either side (the
// default) the submaps hold more of the trees and field edges that fix the pose, and the loop
// passes the RMSE bar at the true pose; 5 m windows, the default before, leave it over the bar.
// Chosen on the seed-3 rural drives, validated on seed 11 (docs/BENCHMARK.md, "Submaps of 10 m
// within a point budget").
TEST(Submap, TenMetresOfNeighboursFitTheVegetationThatFiveLeaveOverTheBar) {
    const SparseRuralRevisit wide(176, 26, sim::SensorModel::kVlp16, 1,
                                  ScanReductionConfig{}.submap_path_m);
    const Verification accepted = wide.VerifySubmaps();
    EXPECT_TRUE(accepted.accepted) << ToString(accepted.reason);
    EXPECT_LT(wide.ErrorM(accepted), 0.1);
    const SparseRuralRevisit narrow(176, 26, sim::SensorModel::kVlp16, 1, 5.0);
    EXPECT_EQ(narrow.VerifySubmaps().reason, RejectReason::kHighRmse);
}

// Scan 263 back to scan 44 on a road with trees. ICP from the second coarse peak, 13 m off,
// slides toward the right pose in plain Gauss-Newton steps and stops 3.4 m short of it after 10
// iterations in each stage, where the road still fits (overlap 0.69 against 0.79). Longer steps
// along the sliding direction (IcpConfig::aligned_step_factor) reach the right pose.
TEST(Submap, LongerStepsAlongASlideReachThePoseThatPlainStepsStopShortOf) {
    const SparseRuralRevisit revisit(263, 44);
    const CoarseQuery coarse(*revisit.query_submap.structure, revisit.config.coarse);
    const auto peaks = CoarseAlign(coarse, *revisit.match_submap.structure);
    ASSERT_GE(peaks.size(), 2u);
    core::Transform start = core::Transform::Identity();
    start.linear() =
        Eigen::AngleAxisd(peaks[1].yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    start.translation() << peaks[1].translation_m, 0.0;
    ASSERT_GT((start.translation() - revisit.truth.translation()).norm(), 10.0)
        << "pick a far peak";
    IcpConfig icp = revisit.config.icp;
    ASSERT_EQ(icp.aligned_step_factor, 1.0);  // the registration's default: plain steps
    const IcpResult plain =
        RefinePointToPlane(revisit.query_submap, revisit.match_submap, start, icp);
    EXPECT_FALSE(plain.converged);
    EXPECT_GT((plain.T_match_query.translation() - revisit.truth.translation()).norm(), 1.0);
    icp.aligned_step_factor = 2.0;
    const IcpResult longer =
        RefinePointToPlane(revisit.query_submap, revisit.match_submap, start, icp);
    EXPECT_TRUE(longer.converged);
    EXPECT_LT((longer.T_match_query.translation() - revisit.truth.translation()).norm(), 0.1);
    EXPECT_LT(longer.iterations, plain.iterations);
}

// The same pair verified: with plain steps in the ambiguity test that half-way pose is a rival
// within the odometry's reach, and the loop is rejected as ambiguous; with the test's longer steps
// (IcpConfig::rival_step_factor) its ICP reaches the accepted pose, and the loop is accepted there.
TEST(Submap, TheAmbiguityTestTakesNoHalfwayPoseForARival) {
    const SparseRuralRevisit revisit(263, 44);
    const Verification verified = revisit.VerifySubmaps(revisit.NearTheTruth());
    EXPECT_TRUE(verified.accepted) << ToString(verified.reason);
    EXPECT_LT(revisit.ErrorM(verified), 0.1);
    VerificationConfig plain = revisit.config;
    plain.icp.rival_step_factor = 1.0;
    EXPECT_EQ(revisit.VerifySubmaps(plain, revisit.NearTheTruth()).reason, RejectReason::kAmbiguous)
        << "pick a pair plain steps reject";
}

}  // namespace
}  // namespace lidarloop::registration

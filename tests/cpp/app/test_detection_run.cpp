// The detect and localise runs: what they return equals what the pipeline gives for the same
// descriptors, and the results folder holds what the outcome says.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include "app_test_utils.hpp"
#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/app/verification_run.hpp"
#include "lidarloop/core/angles.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/kitti_bin.hpp"
#include "lidarloop/io/pose_graph_files.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/io/prepared_scans_file.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/results_csv.hpp"
#include "lidarloop/pipeline/scancontext_method.hpp"
#include "lidarloop/posegraph/optimiser.hpp"
#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/submap.hpp"
#include "lidarloop/registration/verification.hpp"
#include "test_utils.hpp"

namespace lidarloop {
namespace {

std::size_t CsvRows(const std::filesystem::path& file) {
    std::ifstream in(file);
    std::size_t lines = 0;
    for (std::string line; std::getline(in, line);) ++lines;
    return lines - 1;  // header
}

// An accepted candidate at its place (per the odometry) with the given overlap.
registration::Verification AcceptedAt(const core::Transform& T_match_query, double overlap) {
    registration::Verification verdict;
    verdict.accepted = true;
    verdict.T_match_query = T_match_query;
    verdict.overlap.query_fraction = overlap;
    verdict.overlap.match_fraction = overlap;
    return verdict;
}

TEST(RejectLoopsAgainstOdometry, RejectsThePoseTheOdometryContradictsAndChoosesAgain) {
    // A straight drive, a scan every metre; the path is the odometry's.
    std::vector<core::StampedPose> odometry(100);
    std::vector<double> path_m(100);
    for (std::size_t i = 0; i < odometry.size(); ++i) {
        odometry[i].T_world_sensor.translation().x() = static_cast<double>(i);
        path_m[i] = static_cast<double>(i);
    }
    const auto T_match_query = [&](std::size_t match, std::size_t query) {
        return odometry[match].T_world_sensor.inverse() * odometry[query].T_world_sensor;
    };
    core::Transform period_off = core::Transform::Identity();
    period_off.translation().x() = 45.0;  // a street that repeats itself every 45 m

    pipeline::LoopQuery two_loops;  // the wrong pose overlaps better: it was the loop
    two_loops.query = 99;
    two_loops.candidates = {{40, 0.1}, {45, 0.2}, {50, 0.3}};
    two_loops.verifications = {AcceptedAt(T_match_query(40, 99), 0.4),
                               AcceptedAt(T_match_query(45, 99) * period_off, 0.6),
                               registration::Verification{}};
    two_loops.verifications[2].reason = registration::RejectReason::kLowOverlap;
    two_loops.accepted = true;
    ASSERT_EQ(two_loops.loop(), 1u);
    pipeline::LoopQuery one_wrong_loop = two_loops;
    one_wrong_loop.query = 98;
    one_wrong_loop.candidates.resize(1);
    one_wrong_loop.verifications = {AcceptedAt(T_match_query(40, 98) * period_off, 0.5)};

    std::vector<pipeline::LoopQuery> queries{two_loops, one_wrong_loop};
    EXPECT_EQ(app::RejectLoopsAgainstOdometry(queries, odometry, path_m, {}), 2u);
    EXPECT_EQ(queries[0].loop(), 0u);
    EXPECT_TRUE(queries[0].accepted);
    EXPECT_EQ(queries[0].verifications[1].reason, registration::RejectReason::kOdometryMismatch);
    EXPECT_FALSE(queries[0].verifications[1].accepted);
    EXPECT_EQ(queries[0].verifications[2].reason, registration::RejectReason::kLowOverlap);
    EXPECT_FALSE(queries[1].accepted);
    EXPECT_EQ(queries[1].loop(), std::nullopt);
    EXPECT_EQ(registration::ToString(registration::RejectReason::kOdometryMismatch),
              "odometry_mismatch");

    // Loops the odometry agrees with stay; a scan without odometry is an error.
    std::vector<pipeline::LoopQuery> consistent{two_loops};
    consistent[0].verifications[1] = AcceptedAt(T_match_query(45, 99), 0.6);
    EXPECT_EQ(app::RejectLoopsAgainstOdometry(consistent, odometry, path_m, {}), 0u);
    EXPECT_EQ(consistent[0].loop(), 1u);
    // A scan the odometry lost (not finite) cannot be judged: its wrong loop stays.
    std::vector<core::StampedPose> lost = odometry;
    lost[45].T_world_sensor.translation().x() = std::numeric_limits<double>::quiet_NaN();
    std::vector<pipeline::LoopQuery> unjudged{two_loops};
    EXPECT_EQ(app::RejectLoopsAgainstOdometry(unjudged, lost, path_m, {}), 0u);
    EXPECT_EQ(unjudged[0].loop(), 1u);
    // The check's allowed poses: those of the gate, where the odometry knows both scans.
    const pipeline::LoopCheck check = app::OdometryLoopCheck(lost, path_m, {});
    const registration::PoseAllowed allowed = check.AllowedPoses(99, 40);
    ASSERT_TRUE(allowed);
    EXPECT_TRUE(allowed(T_match_query(40, 99)));
    EXPECT_FALSE(allowed(T_match_query(40, 99) * period_off));
    EXPECT_FALSE(check.AllowedPoses(99, 45));
    EXPECT_FALSE(check.AllowedPoses(45, 40));
    odometry.resize(60);
    EXPECT_THROW(app::RejectLoopsAgainstOdometry(consistent, odometry, path_m, {}),
                 core::ConfigError);
}

// A fit of `query` on `match` that a test other than the fit's own rejected.
registration::Verification FitRejectedAs(registration::RejectReason reason,
                                         const core::Transform& T_match_query) {
    registration::Verification verdict = AcceptedAt(T_match_query, 0.6);
    verdict.accepted = false;
    verdict.reason = reason;
    verdict.registered_hypotheses = 1;
    return verdict;
}

// A planar pose: x, y metres, yaw radians.
core::Transform PlanarPose(double x_m, double y_m, double yaw_rad) {
    core::Transform pose = core::Transform::Identity();
    pose.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pose.translation() = Eigen::Vector3d(x_m, y_m, 0.0);
    return pose;
}

// A road driven along x, a scan every metre, the heading wobbling a little: the odometry's
// relative poses turn as well as move.
std::vector<core::StampedPose> WobblingRoad(std::size_t scans) {
    std::vector<core::StampedPose> odometry(scans);
    for (std::size_t i = 0; i < scans; ++i) {
        const auto x_m = static_cast<double>(i);
        odometry[i].T_world_sensor = PlanarPose(x_m, 0.0, 0.05 * std::sin(0.7 * x_m));
    }
    return odometry;
}

// A street that looks alike along its length: a query 900 m of path on, driving back the other
// way, registers on several scans of the place. A loop that slides along the street passes the
// gate (its allowance grows with the path), but not the fits of the candidates ranked before it,
// whose matches the odometry relates over a few metres: the query's fits vote
// (docs/verification.md).
TEST(RejectLoopsAgainstOdometry, ALoopMustAgreeWithMostOfTheQuerysEarlierFits) {
    std::vector<core::StampedPose> odometry = WobblingRoad(1000);
    std::vector<double> path_m(1000);
    for (std::size_t i = 0; i < path_m.size(); ++i) path_m[i] = static_cast<double>(i);
    // The query revisits scan 40's place turned round; its odometry has drifted 4 m and 1 degree.
    const core::Transform T_40_query = PlanarPose(1.0, 3.0, 3.1);
    odometry[999].T_world_sensor =
        odometry[40].T_world_sensor * T_40_query * PlanarPose(4.0, 0.5, 0.017);
    const auto at_place = [&](std::size_t match) {
        return odometry[match].T_world_sensor.inverse() * odometry[40].T_world_sensor * T_40_query;
    };
    const core::Transform slide = PlanarPose(9.0, 0.0, 0.0);
    const auto Loop = [&](std::vector<registration::Verification> earlier,
                          const core::Transform& T_match_query) {
        pipeline::LoopQuery query;
        query.query = 999;
        for (std::size_t c = 0; c < earlier.size(); ++c) query.candidates.push_back({40 + c, 0.1});
        query.candidates.push_back({46, 0.2});
        query.verifications = std::move(earlier);
        query.verifications.push_back(AcceptedAt(T_match_query, 0.5));
        query.accepted = true;
        return query;
    };
    const auto Kept = [&](pipeline::LoopQuery query) {
        std::vector<pipeline::LoopQuery> queries{std::move(query)};
        EXPECT_EQ(app::RejectLoopsAgainstOdometry(queries, odometry, path_m, {}), 0u);
        const registration::Verification& loop = queries[0].verifications.back();
        EXPECT_EQ(queries[0].accepted, queries[0].loop().has_value());
        EXPECT_TRUE(loop.accepted || loop.reason == registration::RejectReason::kUnlikeFits);
        return loop.accepted;
    };
    using registration::RejectReason;
    const auto too_far = [&](std::size_t match, const core::Transform& slid) {
        return FitRejectedAs(RejectReason::kTooFar, at_place(match) * slid);
    };
    const auto ambiguous = [&](std::size_t match, const core::Transform& slid) {
        return FitRejectedAs(RejectReason::kAmbiguous, at_place(match) * slid);
    };
    const core::Transform none = core::Transform::Identity();
    // The slid loop passes the gate alone; against the query's fits it must win the vote.
    EXPECT_TRUE(Kept(Loop({}, at_place(46) * slide)));
    EXPECT_TRUE(Kept(Loop({too_far(40, none)}, at_place(46))));
    EXPECT_FALSE(Kept(Loop({too_far(40, none)}, at_place(46) * slide)));
    EXPECT_TRUE(Kept(Loop({too_far(40, none), too_far(41, slide)}, at_place(46) * slide)));
    EXPECT_FALSE(Kept(Loop({too_far(40, none), ambiguous(41, none)}, at_place(46) * slide)));
    // A fit with a rival counts half: either pose may be the place.
    EXPECT_TRUE(Kept(Loop({ambiguous(40, none)}, at_place(46) * slide)));
    EXPECT_FALSE(Kept(Loop({ambiguous(40, none), ambiguous(41, none)}, at_place(46) * slide)));
    EXPECT_TRUE(Kept(Loop({ambiguous(40, none), ambiguous(41, none), too_far(42, slide)},
                          at_place(46) * slide)));
    // An earlier accepted fit votes fully; one the vote rejected does not vote.
    EXPECT_FALSE(Kept(Loop({AcceptedAt(at_place(40), 0.4)}, at_place(46) * slide)));
    EXPECT_TRUE(
        Kept(Loop({FitRejectedAs(RejectReason::kUnlikeFits, at_place(40))}, at_place(46) * slide)));
    // No vote: a fit that failed its own tests, a too-far verdict without a registration, a fit
    // the odometry contradicts, or a candidate ranked after the loop.
    EXPECT_TRUE(Kept(Loop({FitRejectedAs(RejectReason::kLowOverlap, at_place(40)),
                           FitRejectedAs(RejectReason::kDegenerate, at_place(41))},
                          at_place(46) * slide)));
    registration::Verification unregistered = too_far(40, none);
    unregistered.registered_hypotheses = 0;
    EXPECT_TRUE(Kept(Loop({unregistered}, at_place(46) * slide)));
    EXPECT_TRUE(Kept(Loop({too_far(40, PlanarPose(0.0, 80.0, 0.0))}, at_place(46) * slide)));
    pipeline::LoopQuery loop_first = Loop({}, at_place(46) * slide);
    loop_first.candidates.push_back({40, 0.3});
    loop_first.verifications.push_back(too_far(40, none));
    std::vector<pipeline::LoopQuery> queries{loop_first};
    app::RejectLoopsAgainstOdometry(queries, odometry, path_m, {});
    EXPECT_TRUE(queries[0].verifications.front().accepted);
    // A loop found before the candidates ranked before it are decided (a cached verdict, in rank
    // order) is judged once they are, by all their votes.
    EXPECT_TRUE(
        Kept(Loop({too_far(40, none), registration::Verification{}}, at_place(46) * slide)));
    EXPECT_FALSE(Kept(Loop({too_far(40, none), too_far(41, none)}, at_place(46) * slide)));
}

// A revisit along the wobbling road: queries 150-169 come back to scans 20-39 turned round (3 m
// to the side), their odometry 0.5 m, 1 m and 1 degree off. Loops of one revisit that agree form
// chains: a run of loops slid 12 m along the road, one tree period, is a chain of its own,
// shorter than the right one.
class RevisitChains : public ::testing::Test {
protected:
    RevisitChains() : odometry(WobblingRoad(200)), path_m(200) {
        for (std::size_t i = 0; i < path_m.size(); ++i) path_m[i] = static_cast<double>(i);
        for (std::size_t query = 150; query < 170; ++query)
            odometry[query].T_world_sensor = TruePlace(query) * PlanarPose(0.5, 1.0, 0.017);
    }
    static core::Transform TruePlace(std::size_t query) {
        const double x_m = static_cast<double>(query) - 130.0;
        return PlanarPose(x_m, 3.0, 3.1 + 0.01 * x_m);
    }
    // Query's loop to scan `match` (the first pass: its odometry is the truth), slid along the
    // road by `slide_m`.
    pipeline::LoopQuery LoopTo(std::size_t query, std::size_t match, double slide_m) const {
        pipeline::LoopQuery loop;
        loop.query = query;
        loop.candidates = {{match, 0.1}};
        loop.verifications = {AcceptedAt(odometry[match].T_world_sensor.inverse() *
                                             TruePlace(query) * PlanarPose(slide_m, 0.0, 0.0),
                                         0.6)};
        loop.accepted = true;
        return loop;
    }
    pipeline::LoopQuery Loop(std::size_t query, double slide_m) const {
        return LoopTo(query, query - 130, slide_m);
    }
    // The queries whose loop stays accepted after the vote within `window_m`.
    std::vector<std::size_t> Kept(std::vector<pipeline::LoopQuery> queries,
                                  double window_m = 10.0) {
        const pipeline::LoopCheck check = app::OdometryLoopCheck(odometry, path_m, {});
        const std::size_t rejected = check.judge_revisits(queries, window_m);
        std::vector<std::size_t> kept;
        std::size_t rejected_counted = 0;
        for (const pipeline::LoopQuery& query : queries) {
            EXPECT_EQ(query.accepted, query.loop().has_value());
            if (query.accepted) kept.push_back(query.query);
            for (const auto& verdict : query.verifications)
                rejected_counted += verdict.reason == registration::RejectReason::kUnlikeRevisit;
        }
        EXPECT_EQ(rejected, rejected_counted);
        std::sort(kept.begin(), kept.end());
        return kept;
    }
    static std::vector<std::size_t> Range(std::size_t first, std::size_t end) {
        std::vector<std::size_t> range;
        for (std::size_t i = first; i < end; ++i) range.push_back(i);
        return range;
    }

    std::vector<core::StampedPose> odometry;
    std::vector<double> path_m;
};

TEST_F(RevisitChains, TheShorterOfTwoChainsThatDisagreeIsRejected) {
    std::vector<pipeline::LoopQuery> queries;
    for (std::size_t query = 150; query < 164; ++query)
        queries.push_back(Loop(query, query < 160 ? 0.0 : 12.0));
    EXPECT_EQ(Kept(queries), Range(150, 160));
    // The order of the queries does not matter.
    std::reverse(queries.begin(), queries.end());
    EXPECT_EQ(Kept(queries), Range(150, 160));
    // A slid run as long as the window, then the right loops: the longer chain wins, though
    // around the first right loops the slid ones are as many as the right ones.
    queries.clear();
    for (std::size_t query = 150; query < 170; ++query)
        queries.push_back(Loop(query, query < 158 ? 12.0 : 0.0));
    EXPECT_EQ(Kept(queries), Range(158, 170));
    // Two loops that disagree with nothing else around: neither can be trusted.
    EXPECT_TRUE(Kept({Loop(150, 0.0), Loop(152, 12.0)}).empty());
    // Alone, or with agreeing loops only, a loop is kept, slid or not (the gate judges it alone).
    EXPECT_EQ(Kept({Loop(160, 12.0)}), (std::vector<std::size_t>{160}));
    EXPECT_EQ(Kept({Loop(160, 12.0), Loop(161, 12.0)}), (std::vector<std::size_t>{160, 161}));
}

TEST_F(RevisitChains, OnlyTheLoopsOfTheRevisitJudge) {
    // Queries 12 m of path apart are of another revisit: with a window of 10 m they do not vote.
    EXPECT_EQ(Kept({Loop(150, 0.0), Loop(162, 12.0)}), (std::vector<std::size_t>{150, 162}));
    EXPECT_TRUE(Kept({Loop(150, 0.0), Loop(162, 12.0)}, 12.0).empty());
    // Matches 12 m apart (query 151 to scan 33 instead of 21), queries 1 m apart: no vote either.
    EXPECT_EQ(Kept({Loop(150, 12.0), LoopTo(151, 33, 0.0)}), (std::vector<std::size_t>{150, 151}));
    // Matches 5 m apart, queries 15 m: no vote.
    EXPECT_EQ(Kept({Loop(150, 0.0), LoopTo(165, 25, 12.0)}), (std::vector<std::size_t>{150, 165}));
    // A scan the odometry lost neither judges nor is judged.
    odometry[152].T_world_sensor.translation().x() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(Kept({Loop(150, 0.0), Loop(152, 12.0)}), (std::vector<std::size_t>{150, 152}));
}

TEST_F(RevisitChains, AQuerysOtherLoopBecomesItsLoop) {
    std::vector<pipeline::LoopQuery> queries;
    for (std::size_t query = 150; query < 160; ++query) queries.push_back(Loop(query, 0.0));
    // Query 155: the slid loop overlaps best, a second candidate holds the right one.
    pipeline::LoopQuery& two = queries[5];
    two.verifications[0] = Loop(155, 12.0).verifications[0];
    two.verifications[0].overlap.query_fraction = 0.9;
    two.verifications[0].overlap.match_fraction = 0.9;
    two.candidates.push_back({26, 0.2});
    two.verifications.push_back(LoopTo(155, 26, 0.0).verifications[0]);
    ASSERT_EQ(two.loop(), 0u);
    const pipeline::LoopCheck check = app::OdometryLoopCheck(odometry, path_m, {});
    EXPECT_EQ(check.judge_revisits(queries, 10.0), 1u);
    EXPECT_EQ(queries[5].verifications[0].reason, registration::RejectReason::kUnlikeRevisit);
    EXPECT_EQ(queries[5].loop(), 1u);
    EXPECT_TRUE(queries[5].accepted);
    EXPECT_EQ(registration::ToString(registration::RejectReason::kUnlikeRevisit), "unlike_revisit");
}

TEST_F(RevisitChains, AChainIsAsLongAsItsQueries) {
    // Two slid loops of each of queries 160-163 (the pose graph's further loops): 8 loops of 4
    // queries, against 6 queries of right loops.
    std::vector<pipeline::LoopQuery> queries;
    for (std::size_t query = 154; query < 160; ++query) queries.push_back(Loop(query, 0.0));
    for (std::size_t query = 160; query < 164; ++query) {
        pipeline::LoopQuery two = Loop(query, 12.0);
        two.candidates.push_back({query - 129, 0.2});
        two.verifications.push_back(LoopTo(query, query - 129, 12.0).verifications[0]);
        queries.push_back(two);
    }
    EXPECT_EQ(Kept(queries), Range(154, 160));
}

// OdometryAllowsALoop against brute force with the pose graph's gate: where it says no loop
// pose within 10 m passes, none of many tried does; where it says one does, the nearest to the
// odometry's does. Odometry 0-80 m apart over 0-400 m of path, turned anyhow.
TEST(OdometryAllowsALoop, EqualsTryingLoopPosesWithinReach) {
    const pipeline::OdometryGate gate = app::OdometryGateOf(posegraph::PoseGraphConfig{});
    constexpr double kMaxLoopM = 10.0;
    std::mt19937 random(5);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const auto random_turn = [&](double max_rad) {
        return Eigen::AngleAxisd{max_rad * unit(random),
                                 Eigen::Vector3d{unit(random), unit(random), 1.0}.normalized()}
            .toRotationMatrix();
    };
    std::size_t ruled_out = 0;
    std::size_t allowed = 0;
    for (int pair = 0; pair < 200; ++pair) {
        std::vector<core::Transform> T_odom_sensor(2, core::Transform::Identity());
        const double length_m = 40.0 * (1.0 + unit(random));
        T_odom_sensor[1].translation() =
            length_m * Eigen::Vector3d{unit(random), unit(random), 0.1}.normalized();
        T_odom_sensor[1].linear() = random_turn(M_PI);
        const std::vector<double> path_m{0.0, 200.0 * (1.0 + unit(random))};
        const auto pose_of = [&](std::size_t i) { return T_odom_sensor[i]; };
        const auto path_of = [&](std::size_t i) { return path_m[i]; };
        const bool may_close =
            pipeline::OdometryAllowsALoop(1, 0, kMaxLoopM, pose_of, path_of, gate);
        const core::Transform T_0_1 = T_odom_sensor[0].inverse() * T_odom_sensor[1];
        if (may_close) {
            ++allowed;
            core::Transform nearest = T_0_1;
            if (nearest.translation().norm() > kMaxLoopM)
                nearest.translation() *= kMaxLoopM / nearest.translation().norm();
            EXPECT_FALSE(gate(nearest, T_0_1, path_m[1])) << pair;
            continue;
        }
        ++ruled_out;
        for (int attempt = 0; attempt < 500; ++attempt) {
            core::Transform loop = core::Transform::Identity();
            const double loop_length_m = kMaxLoopM * std::abs(unit(random));
            loop.translation() =
                loop_length_m *
                Eigen::Vector3d{unit(random), unit(random), unit(random)}.normalized();
            loop.linear() = T_0_1.linear() * random_turn(0.3 * std::abs(unit(random)));
            ASSERT_TRUE(gate(loop, T_0_1, path_m[1])) << pair << " " << attempt;
        }
    }
    EXPECT_GT(ruled_out, 20u);  // both answers were tried
    EXPECT_GT(allowed, 20u);
    // Odometry that does not know a scan cannot rule its loops out.
    const auto lost = [](std::size_t) {
        core::Transform T = core::Transform::Identity();
        T.translation().x() = std::numeric_limits<double>::quiet_NaN();
        return T;
    };
    EXPECT_TRUE(pipeline::OdometryAllowsALoop(
        1, 0, kMaxLoopM, lost, [](std::size_t i) { return 100.0 * static_cast<double>(i); }, gate));
}

// The coarse search's yaw window (OdometryYawWindow) holds the yaw of every loop pose the pose
// graph's gate lets pass: the discrepancy's angle bounds the yaw's, up to the relative tilt of
// the two scans (at most 0.33 degrees more for 10 degrees of it). Random odometry and loops.
TEST(OdometryYawWindow, HoldsTheYawOfEveryLoopTheGatePasses) {
    const posegraph::PoseGraphConfig config;
    const pipeline::OdometryGate gate = app::OdometryGateOf(config);
    std::mt19937 random(9);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const auto turn = [&](double max_rad, double axis_z) {
        return Eigen::AngleAxisd{max_rad * unit(random),
                                 Eigen::Vector3d{unit(random), unit(random), axis_z}.normalized()}
            .toRotationMatrix();
    };
    const auto yaw_of = [](const core::Transform& T) {
        return std::atan2(T.linear()(1, 0), T.linear()(0, 0));
    };
    std::size_t passed = 0;
    for (int pair = 0; pair < 300; ++pair) {
        std::vector<core::Transform> T_odom_sensor(2, core::Transform::Identity());
        T_odom_sensor[1].translation() = 30.0 * Eigen::Vector3d{unit(random), unit(random), 0.0};
        // Any heading, tilted by up to 10 degrees.
        T_odom_sensor[1].linear() =
            Eigen::AngleAxisd(M_PI * unit(random), Eigen::Vector3d::UnitZ()).toRotationMatrix() *
            turn(10.0 * core::kRadiansPerDegree, 0.0);
        const std::vector<double> path_m{0.0, 500.0 * (1.0 + unit(random))};
        const auto pose_of = [&](std::size_t i) { return T_odom_sensor[i]; };
        const auto path_of = [&](std::size_t i) { return path_m[i]; };
        const registration::YawWindow window =
            pipeline::OdometryYawWindow(1, 0, pose_of, path_of, gate);
        const core::Transform T_0_1 = T_odom_sensor[0].inverse() * T_odom_sensor[1];
        ASSERT_FALSE(window.Whole());
        ASSERT_NEAR(window.centre_rad, yaw_of(T_0_1), 1e-12);
        ASSERT_EQ(window.half_width_rad,
                  posegraph::GateRotationDeg(path_m[1], config) * core::kRadiansPerDegree);
        const registration::YawWindow slack{window.centre_rad,
                                            window.half_width_rad + 0.4 * core::kRadiansPerDegree};
        for (int attempt = 0; attempt < 50; ++attempt) {
            core::Transform loop = T_0_1;
            loop.linear() = T_0_1.linear() * turn(0.7, unit(random));  // up to 40 degrees
            if (gate(loop, T_0_1, path_m[1])) continue;
            ++passed;
            ASSERT_TRUE(slack.Contains(yaw_of(loop))) << pair << " " << attempt;
        }
    }
    EXPECT_GT(passed, 1000u);
    // Where the odometry does not know a scan, or the gate says no allowance: every yaw.
    const auto lost = [](std::size_t) {
        core::Transform T = core::Transform::Identity();
        T.translation().x() = std::numeric_limits<double>::quiet_NaN();
        return T;
    };
    const auto path_of = [](std::size_t i) { return 100.0 * static_cast<double>(i); };
    EXPECT_TRUE(pipeline::OdometryYawWindow(1, 0, lost, path_of, gate).Whole());
    pipeline::OdometryGate without = gate;
    without.rotation_allowance_deg = {};
    const auto level = [](std::size_t) { return core::Transform::Identity(); };
    EXPECT_TRUE(pipeline::OdometryYawWindow(1, 0, level, path_of, without).Whole());
    EXPECT_FALSE(pipeline::OdometryYawWindow(1, 0, level, path_of, gate).Whole());
    EXPECT_TRUE(pipeline::LoopCheck{}.YawWindow(1, 0).Whole());
    // The check of `detect --odometry` asks the same.
    std::vector<core::StampedPose> odometry(2);
    odometry[1].T_world_sensor.linear() =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const std::vector<double> path_m{0.0, 100.0};
    const registration::YawWindow asked =
        app::OdometryLoopCheck(odometry, path_m, config).YawWindow(1, 0);
    EXPECT_NEAR(asked.centre_rad, 0.7, 1e-12);
    EXPECT_EQ(asked.half_width_rad,
              posegraph::GateRotationDeg(100.0, config) * core::kRadiansPerDegree);
}

// The candidate search's cheap bound of the pose graph's gate (LoopCheck::in_reach_bound: the
// sensors' distance against the loop's plus the gate's translation allowance) says what
// OdometryAllowsALoop says, also within a millimetre of the reach, and lets through a scan the
// odometry does not know. Odometry turned anyhow, anywhere within 3 km, 0-2 km of path apart.
TEST(OdometryAllowsALoop, TheSearchsBoundSaysTheSame) {
    const posegraph::PoseGraphConfig config;
    const pipeline::OdometryGate gate = app::OdometryGateOf(config);
    constexpr double kMaxLoopM = 10.0;
    std::mt19937 random(6);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::vector<core::Transform> T_odom_sensor(2, core::Transform::Identity());
    std::vector<double> path_m{0.0, 0.0};
    const pipeline::LoopCheck check =
        pipeline::CheckAgainstOdometry([&](std::size_t i) { return T_odom_sensor[i]; },
                                       [&](std::size_t i) { return path_m[i]; }, gate);
    ASSERT_TRUE(check.in_reach_bound);
    std::size_t in_reach = 0;
    const auto random_turn = [&] {
        return Eigen::AngleAxisd{M_PI * unit(random),
                                 Eigen::Vector3d{unit(random), unit(random), 1.0}.normalized()}
            .toRotationMatrix();
    };
    for (int pair = 0; pair < 2000; ++pair) {
        path_m[0] = 5000.0 * (1.0 + unit(random));
        path_m[1] = path_m[0] + 1000.0 * (1.0 + unit(random));
        const double reach_m =
            kMaxLoopM + posegraph::GateTranslationM(path_m[1] - path_m[0], config);
        // A quarter within a millimetre of the reach, the rest anywhere up to twice it.
        const double distance_m =
            pair % 4 == 0 ? reach_m + 1e-3 * unit(random) : reach_m * (1.0 + unit(random));
        T_odom_sensor[0].linear() = random_turn();
        T_odom_sensor[0].translation() =
            3000.0 * Eigen::Vector3d{unit(random), unit(random), 0.01 * unit(random)};
        T_odom_sensor[1].linear() = random_turn();
        T_odom_sensor[1].translation() =
            T_odom_sensor[0].translation() +
            distance_m * Eigen::Vector3d{unit(random), unit(random), 0.2}.normalized();
        const bool may_close = pipeline::OdometryAllowsALoop(
            1, 0, kMaxLoopM, [&](std::size_t i) { return T_odom_sensor[i]; },
            [&](std::size_t i) { return path_m[i]; }, gate);
        // Never ruling out a scan that may close; ruling out the others but within a tenth of
        // a millimetre of the reach, where rounding and the bound's slack may go either way.
        // The reach is exactly where OdometryAllowsALoop changes its answer.
        const bool bound = check.in_reach_bound(1, 0, kMaxLoopM);
        if (may_close) {
            EXPECT_TRUE(bound) << pair << ": " << distance_m << " m of " << reach_m;
        }
        if (distance_m > reach_m + 1e-4) {
            EXPECT_FALSE(bound || may_close) << pair;
        }
        if (distance_m < reach_m - 1e-4) {
            EXPECT_TRUE(may_close) << pair;
        }
        in_reach += may_close ? 1 : 0;
    }
    EXPECT_GT(in_reach, 500u);  // both answers were tried
    EXPECT_LT(in_reach, 1500u);
    T_odom_sensor[1].translation().x() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_TRUE(check.in_reach_bound(1, 0, kMaxLoopM));
    // Nor does an allowance that is not a number rule a scan out.
    T_odom_sensor[1].translation() = Eigen::Vector3d(1e6, 0.0, 0.0);
    pipeline::OdometryGate unknown = gate;
    unknown.translation_allowance_m = [](double) { return std::nan(""); };
    EXPECT_TRUE(pipeline::CheckAgainstOdometry([&](std::size_t i) { return T_odom_sensor[i]; },
                                               [&](std::size_t i) { return path_m[i]; }, unknown)
                    .in_reach_bound(1, 0, kMaxLoopM));
    EXPECT_FALSE(check.in_reach_bound(1, 0, kMaxLoopM));
}

// A run's one note, which must say `text` (fatal when there is not exactly one).
// Note i holds texts[i], and there are no other notes.
void ExpectNotesSaying(const std::vector<std::string>& notes,
                       const std::vector<std::string>& texts) {
    ASSERT_EQ(notes.size(), texts.size());
    for (std::size_t i = 0; i < notes.size(); ++i)
        EXPECT_TRUE(test::Contains(notes[i], texts[i])) << notes[i];
}

void ExpectOneNoteSaying(const std::vector<std::string>& notes, const std::string& text) {
    ExpectNotesSaying(notes, {text});
}

// What a run without --odometry says of the small sequence's poses_odometry.txt.
constexpr const char* kUnusedOdometry = "poses_odometry.txt is not read: give it as the odometry";

// The submap window, metres, that a run wrote into out/config.yaml.
double WrittenSubmapPathM(const std::filesystem::path& out) {
    return io::LoadConfigYaml(out / "config.yaml").detection.verification.reduction.submap_path_m;
}

class DetectionRun : public ::testing::Test {
protected:
    void SetUp() override { dataset_.emplace(test::SmallSequence(dir_ / "sequence")); }
    app::DetectRequest Request(const std::string& out, core::Method method) const {
        app::DetectRequest request;
        request.config.descriptor.method = method;
        request.config.detection.min_gap.value = 10;
        // Two candidates per scan: every test verifies its detections, and registration is
        // the slow part under the sanitizers.
        request.config.detection.top_k = 2;
        request.out = dir_ / out;
        return request;
    }
    // The evaluation of one method with `detect`'s config and odometry, into `out`.
    app::EvaluationRequest EvaluationLike(const app::DetectRequest& detect,
                                          const std::string& out) const {
        app::EvaluationRequest evaluate;
        evaluate.config = detect.config;
        evaluate.methods = {detect.config.descriptor.method};
        evaluate.odometry_file = detect.odometry_file;
        evaluate.out = dir_ / out;
        return evaluate;
    }
    // An odometry twice as far apart as the sequence's poses, written to odometry.txt.
    std::vector<core::StampedPose> WriteDoubledOdometry() const {
        std::vector<core::StampedPose> odometry = dataset_->poses();
        for (auto& pose : odometry) pose.T_world_sensor.translation() *= 2.0;
        io::WriteTumPoses(dir_ / "odometry.txt", odometry);
        return odometry;
    }

    test::TempDir dir_;
    std::optional<io::Dataset> dataset_;
};

TEST_F(DetectionRun, EqualsThePipelineOnTheSameDescriptors) {
    for (core::Method method :
         {core::Method::kRange, core::Method::kNdt, pipeline::ScanContextMethod::kMethod}) {
        app::DetectRequest request = Request("detect_" + core::ToString(method), method);
        request.config.detection.verify = false;  // the descriptor's own decision
        if (method == pipeline::ScanContextMethod::kMethod) {
            // Its default 0.13 accepts no scan of this short, thinned sequence; on the demo
            // sequence its best MCC is at 0.27.
            request.config.detection.threshold = 0.27;
        }
        const app::DetectOutcome outcome = app::RunDetect(*dataset_, request);
        const auto described =
            pipeline::DescribeSequence(app::SourceOf(*dataset_), request.config.descriptor);
        const double threshold = request.config.detection.ThresholdFor(method);
        // detect measures the path rule on the dataset's poses.
        const auto expected = pipeline::DetectFromMatrix(
            pipeline::ComputeSimilarityMatrix(described.database), described.database.times_s(),
            request.config.detection, method, core::CumulativePathM(dataset_->poses()));
        ASSERT_EQ(outcome.queries.size(), expected.size());
        std::size_t with_match = 0;
        for (std::size_t i = 0; i < expected.size(); ++i) {
            ASSERT_EQ(outcome.queries[i].candidates.size(), expected[i].candidates.size());
            for (std::size_t r = 0; r < expected[i].candidates.size(); ++r) {
                EXPECT_EQ(outcome.queries[i].candidates[r].index, expected[i].candidates[r].index);
            }
            EXPECT_EQ(outcome.queries[i].accepted, expected[i].accepted);
            with_match += expected[i].has_match() ? 1 : 0;
        }
        EXPECT_EQ(outcome.threshold, threshold);
        EXPECT_GT(outcome.accepted, 0U);
        EXPECT_EQ(CsvRows(request.out / "loops.csv"), with_match);
        for (const char* file : {"candidates.csv", "similarity.bin", "similarity.png",
                                 "database.lldb", "config.yaml", "timings.json"}) {
            EXPECT_TRUE(std::filesystem::exists(request.out / file)) << file;
        }
        EXPECT_FALSE(std::filesystem::exists(request.out / "skipped.txt"));
    }
}

// Past the memory budget of the similarity matrix, detect finds the same loops without it and
// writes neither similarity.bin nor the images.
TEST_F(DetectionRun, WithoutTheMatrixGivesTheSameResults) {
    for (core::Method method :
         {core::Method::kRange, core::Method::kNdt, pipeline::ScanContextMethod::kMethod}) {
        app::DetectRequest with = Request("with_" + core::ToString(method), method);
        with.config.detection.verify = false;
        app::DetectRequest without = with;
        without.out = dir_ / ("without_" + core::ToString(method));
        without.config.output.similarity_matrix_mib = 0;
        const app::DetectOutcome a = app::RunDetect(*dataset_, with);
        const app::DetectOutcome b = app::RunDetect(*dataset_, without);
        ASSERT_EQ(a.queries.size(), b.queries.size());
        for (std::size_t i = 0; i < a.queries.size(); ++i) {
            ASSERT_EQ(a.queries[i].candidates.size(), b.queries[i].candidates.size()) << i;
            for (std::size_t r = 0; r < a.queries[i].candidates.size(); ++r) {
                EXPECT_EQ(a.queries[i].candidates[r].index, b.queries[i].candidates[r].index);
                EXPECT_EQ(a.queries[i].candidates[r].distance, b.queries[i].candidates[r].distance);
            }
            EXPECT_EQ(a.queries[i].accepted, b.queries[i].accepted) << i;
        }
        EXPECT_EQ(a.accepted, b.accepted);
        EXPECT_EQ(test::ReadFile(with.out / "loops.csv"),
                  test::ReadFile(without.out / "loops.csv"));
        EXPECT_EQ(test::ReadFile(with.out / "candidates.csv"),
                  test::ReadFile(without.out / "candidates.csv"));
        for (const char* file : {"similarity.bin", "similarity.png", "similarity_distance.png"}) {
            EXPECT_TRUE(std::filesystem::exists(with.out / file)) << file;
            EXPECT_FALSE(std::filesystem::exists(without.out / file)) << file;
        }
    }
}

TEST_F(DetectionRun, LocalisingTheSequenceAgainstItsOwnMapFindsEveryScanItself) {
    // Two verified runs; localisation runs under the sanitizers in
    // LocalisationTakesTheMapsThresholdUnlessGivenOne and ScanContextRuns, verification in
    // ReportsProgressOfEveryScanAndEndsTheStage.
    LIDARLOOP_RELEASE_SUITE_ONLY();
    app::DetectRequest detect = Request("detect", core::Method::kRange);
    detect.config.detection.top_k = 1;
    // How the map's scans were merged is the map's affair: the queries need not say it again.
    detect.config.detection.verification.reduction.submap_max_points = 500'000;
    app::RunDetect(*dataset_, detect);
    app::DetectRequest localise = Request("localise", core::Method::kRange);
    localise.config.detection.top_k = 1;  // itself, verified at the identity
    const app::DetectOutcome outcome =
        app::RunLocalise(*dataset_, app::LoadMap(detect.out / "database.lldb"), localise);
    EXPECT_EQ(outcome.map_scans, dataset_->size());
    ASSERT_EQ(outcome.queries.size(), dataset_->size());
    for (const pipeline::LoopQuery& q : outcome.queries) {
        ASSERT_TRUE(q.has_match());
        EXPECT_EQ(q.candidates.front().distance, 0.0) << "scan " << q.query;
    }
    EXPECT_EQ(outcome.accepted, dataset_->size());
}

// Against a map of scans alone the queries are verified alone, with the odometry too (a submap
// on one side only is lopsided), and the run says why.
TEST_F(DetectionRun, AgainstAMapOfScansAloneTheQueriesAreAlone) {
    LIDARLOOP_RELEASE_SUITE_ONLY();  // two verified runs
    app::DetectRequest detect = Request("detect", core::Method::kRange);
    detect.config.detection.top_k = 1;
    detect.config.detection.verification.reduction.submap_path_m = 0.0;
    app::RunDetect(*dataset_, detect);
    app::DetectRequest localise = Request("localise", core::Method::kRange);
    localise.config.detection.top_k = 1;  // itself, verified at the identity
    localise.odometry_file = dir_ / "sequence" / "poses_odometry.txt";
    const app::DetectOutcome outcome =
        app::RunLocalise(*dataset_, app::LoadMap(detect.out / "database.lldb"), localise);
    EXPECT_TRUE(std::any_of(outcome.notes.begin(), outcome.notes.end(), [](const auto& note) {
        return test::Contains(note, "the map's scans are alone");
    }));
    EXPECT_EQ(WrittenSubmapPathM(localise.out), 0.0);
    EXPECT_EQ(outcome.accepted, dataset_->size());
}

// The online detector verifies scans alone, so the map saved from it records scans alone, and
// a localisation against it, without odometry, prepares its queries alone and says why.
TEST_F(DetectionRun, AnOnlineDetectorsMapIsOfScansAlone) {
    LIDARLOOP_RELEASE_SUITE_ONLY();  // verified processing and a verified localisation
    pipeline::DetectorConfig detection;
    detection.min_gap.value = 10;
    detection.top_k = 1;
    pipeline::LoopDetector detector(core::DescriptorConfig{}, detection);
    for (std::size_t i = 0; i < 30; ++i)
        detector.Process(dataset_->LoadScan(i), static_cast<double>(i));
    app::SaveDetectorMap(detector, dir_ / "online.lldb");
    const app::LoadedMap map = app::LoadMap(dir_ / "online.lldb");
    ASSERT_TRUE(map.scans);
    EXPECT_EQ(map.scans->scans.size(), 30u);
    EXPECT_EQ(map.scans->reduction.submap_path_m, 0.0);
    EXPECT_EQ(map.detection.verification.reduction.submap_path_m, 0.0);
    app::DetectRequest localise = Request("localise", core::Method::kRange);
    localise.config.detection.top_k = 1;
    const app::DetectOutcome outcome =
        app::RunLocalise(*dataset_, app::LoadMap(dir_ / "online.lldb"), localise);
    ASSERT_NO_FATAL_FAILURE(ExpectOneNoteSaying(outcome.notes, "the map's scans are alone"));
}

TEST_F(DetectionRun, LocalisationTakesTheMapsThresholdUnlessGivenOne) {
    app::DetectRequest detect = Request("detect", core::Method::kRange);
    detect.config.detection.threshold = 0.002;
    detect.config.detection.verify = false;  // thresholds only
    app::RunDetect(*dataset_, detect);
    app::DetectRequest localise = Request("localise", core::Method::kRange);
    localise.config.detection.verify = false;
    const auto map = [&] { return app::LoadMap(detect.out / "database.lldb"); };
    EXPECT_EQ(app::RunLocalise(*dataset_, map(), localise).threshold, 0.002);
    localise.config.detection.threshold = 0.003;
    EXPECT_EQ(app::RunLocalise(*dataset_, map(), localise).threshold, 0.003);
    detect.config.detection.threshold.reset();
    app::RunDetect(*dataset_, detect);
    localise.config.detection.threshold.reset();
    EXPECT_EQ(app::RunLocalise(*dataset_, map(), localise).threshold, 0.005);
}

TEST_F(DetectionRun, AMapDescribedOtherwiseIsAClearError) {
    app::DetectRequest detect = Request("detect", core::Method::kRange);
    detect.config.detection.verify = false;  // the descriptor check comes first
    app::RunDetect(*dataset_, detect);
    app::DetectRequest localise = Request("localise", core::Method::kRange);
    localise.config.descriptor.histogram.bins = 50;
    EXPECT_THROW(app::RunLocalise(*dataset_, app::LoadMap(detect.out / "database.lldb"), localise),
                 core::ConfigError);
    EXPECT_FALSE(std::filesystem::exists(localise.out));
}

// A CSV file as rows of fields by column name.
std::vector<std::map<std::string, std::string>> ReadCsv(const std::filesystem::path& file) {
    std::ifstream in(file);
    const auto split = [](const std::string& line) {
        std::vector<std::string> fields(1);
        for (const char c : line) {
            if (c == ',') {
                fields.emplace_back();
            } else {
                fields.back() += c;
            }
        }
        return fields;
    };
    std::string line;
    std::getline(in, line);
    const auto header = split(line);
    std::vector<std::map<std::string, std::string>> rows;
    while (std::getline(in, line)) {
        const auto fields = split(line);
        EXPECT_EQ(fields.size(), header.size()) << line;
        auto& row = rows.emplace_back();
        for (std::size_t i = 0; i < std::min(fields.size(), header.size()); ++i)
            row[header[i]] = fields[i];
    }
    return rows;
}

// A verified row of loops.csv or candidates.csv states the verdict of its candidate: the pose,
// the fit and the reason, as printed to 9 digits; a candidate never registered has none.
void ExpectRowIsTheVerdict(const std::map<std::string, std::string>& row,
                           const registration::Verification& v) {
    const auto number = [&](const char* column) { return std::stod(row.at(column)); };
    EXPECT_EQ(row.at("reason"), registration::ToString(v.reason));
    // Empty pose and fit fields exactly when nothing was registered.
    EXPECT_EQ(row.at("tx").empty(), !v.Registered()) << row.at("reason");
    if (row.at("tx").empty()) return;
    const Eigen::Quaterniond q(number("qw"), number("qx"), number("qy"), number("qz"));
    core::Transform T = core::Transform::Identity();
    T.linear() = q.toRotationMatrix();
    T.translation() << number("tx"), number("ty"), number("tz");
    EXPECT_LT((T.matrix() - v.T_match_query.matrix()).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_NEAR(number("overlap_query"), v.overlap.query_fraction, 1e-8);
    EXPECT_NEAR(number("overlap_match"), v.overlap.match_fraction, 1e-8);
    EXPECT_NEAR(number("distinctive_query"), v.overlap.query_distinctive_fraction, 1e-8);
    EXPECT_NEAR(number("distinctive_match"), v.overlap.match_distinctive_fraction, 1e-8);
    EXPECT_NEAR(number("rmse_m"), v.overlap.rmse_m, 1e-8);
    if (!std::isnan(v.shifted_overlap_ratio)) {
        EXPECT_NEAR(number("shifted_overlap"), v.shifted_overlap_ratio, 1e-8);
    }
}

// candidates.csv holds every candidate's verdict, loops.csv each query's loop (the accepted
// candidate that overlaps best, else the first), and timings.json counts the pairs registered and
// the bytes of the prepared scans (those saved in database.scans).
void ExpectFilesStateTheVerdicts(const app::DetectRequest& request,
                                 const app::DetectOutcome& outcome, const io::Dataset& dataset) {
    const auto candidates = ReadCsv(request.out / "candidates.csv");
    std::size_t row = 0, registered = 0;
    for (const pipeline::LoopQuery& q : outcome.queries) {
        for (std::size_t r = 0; r < q.candidates.size(); ++r, ++row) {
            ASSERT_LT(row, candidates.size());
            EXPECT_EQ(std::stoul(candidates[row].at("query")), q.query);
            EXPECT_EQ(std::stoul(candidates[row].at("match")), q.candidates[r].index);
            EXPECT_EQ(candidates[row].at("accepted"), q.verifications[r].accepted ? "1" : "0");
            ExpectRowIsTheVerdict(candidates[row], q.verifications[r]);
            registered += q.verifications[r].reason != registration::RejectReason::kPruned;
        }
    }
    EXPECT_EQ(row, candidates.size());
    const auto loops = ReadCsv(request.out / "loops.csv");
    std::size_t loop_row = 0;
    for (const pipeline::LoopQuery& q : outcome.queries) {
        if (!q.has_match()) continue;
        ASSERT_LT(loop_row, loops.size());
        const auto& loop = loops[loop_row++];
        // The loop: the accepted candidate that overlaps best (the first of equals), else rank 1.
        std::size_t rank = 0;
        double best_overlap = -1.0;
        for (std::size_t r = 0; r < q.candidates.size(); ++r) {
            const registration::Verification& v = q.verifications[r];
            if (v.accepted &&
                std::min(v.overlap.query_fraction, v.overlap.match_fraction) > best_overlap) {
                rank = r;
                best_overlap = std::min(v.overlap.query_fraction, v.overlap.match_fraction);
            }
        }
        EXPECT_EQ(std::stoul(loop.at("query")), q.query);
        EXPECT_EQ(std::stoul(loop.at("rank")), rank + 1) << q.query;
        EXPECT_EQ(std::stoul(loop.at("match")), q.candidates[rank].index) << q.query;
        EXPECT_EQ(loop.at("accepted"), q.accepted ? "1" : "0") << q.query;
        ExpectRowIsTheVerdict(loop, q.verifications[rank]);
    }
    EXPECT_EQ(loop_row, loops.size());

    std::ifstream timings_file(request.out / "timings.json");
    const nlohmann::json timings = nlohmann::json::parse(timings_file)["verification"];
    EXPECT_EQ(timings["pairs_verified"].get<std::size_t>(), registered);
    // The bytes of the scans detect prepared and kept compact, from what it saved in
    // database.scans.
    std::vector<double> bytes;
    for (const auto& scan : io::LoadPreparedScans(request.out / "database.scans").scans) {
        const registration::CompactPreparedScan kept(scan);
        if (scan.structure) bytes.push_back(static_cast<double>(kept.MemoryBytes()));
    }
    ASSERT_EQ(bytes.size(), dataset.size());
    std::sort(bytes.begin(), bytes.end());
    EXPECT_EQ(timings["bytes_per_prepared_scan"]["max"].get<double>(), bytes.back());
    for (const char* step : {"prepare_ms_per_scan", "verify_ms_per_pair"}) {
        EXPECT_GT(timings[step]["median"].get<double>(), 0.0) << step;
    }
}

// Verification inside detect gives what registering each candidate on its own gives, and the
// same verdicts and poses within a centimetre as the scans at full precision.
TEST_F(DetectionRun, VerifiesEveryCandidateAsRegisteringThePairAlone) {
    // Each sampled pair is registered twice more; detection's verification runs under the
    // sanitizers in ReportsProgressOfEveryScanAndEndsTheStage.
    LIDARLOOP_RELEASE_SUITE_ONLY();
    app::DetectRequest request = Request("verified", core::Method::kRange);
    request.config.detection.verification.reduction.submap_path_m = 0.0;  // each scan alone
    request.config.detection.stop_at_first_loop = false;
    const app::DetectOutcome outcome = app::RunDetect(*dataset_, request);
    const registration::VerificationConfig& config = request.config.detection.verification;
    std::size_t checked = 0, accepted = 0;
    for (const pipeline::LoopQuery& q : outcome.queries) {
        ASSERT_EQ(q.verifications.size(), q.candidates.size()) << q.query;
        bool any = false;
        for (std::size_t r = 0; r < q.candidates.size(); ++r) {
            const registration::Verification& v = q.verifications[r];
            any = any || v.accepted;
            if (q.query % 17 != 0) continue;  // a sample: each pair is a registration
            const core::PointCloud query = dataset_->LoadScan(q.query);
            const core::PointCloud match = dataset_->LoadScan(q.candidates[r].index);
            const registration::Verification alone = test::VerifyAsKept(query, match, config);
            EXPECT_EQ(v.accepted, alone.accepted) << q.query << " " << r;
            EXPECT_EQ(v.reason, alone.reason) << q.query << " " << r;
            EXPECT_TRUE(v.T_match_query.isApprox(alone.T_match_query, 1e-9));
            const registration::Verification full = registration::VerifyPair(query, match, config);
            EXPECT_EQ(v.accepted, full.accepted) << q.query << " " << r;
            if (v.accepted && full.accepted) {
                EXPECT_LT((v.T_match_query.translation() - full.T_match_query.translation()).norm(),
                          0.01);
            }
            ++checked;
        }
        EXPECT_EQ(q.accepted, any) << q.query;
        accepted += q.accepted ? 1 : 0;
    }
    EXPECT_GT(checked, 20u);
    EXPECT_EQ(outcome.accepted, accepted);
    EXPECT_EQ(CsvRows(request.out / "candidates.csv"), [&] {
        std::size_t rows = 0;
        for (const auto& q : outcome.queries) rows += q.candidates.size();
        return rows;
    }());
    ExpectFilesStateTheVerdicts(request, outcome, *dataset_);
}

// A scan file emptied to zero bytes reads as a scan without points; the skip message names the
// file, as it does for a file that cannot be read.
TEST(DescribeDataset, AnEmptiedScanFileIsNamedInTheSkipMessage) {
    test::TempDir dir;
    for (int i = 0; i < 4; ++i) {
        const auto file = dir / ("scan" + std::to_string(i) + ".bin");
        io::WriteKittiBin(file, test::RandomCloud(200, static_cast<unsigned>(i)));
    }
    std::filesystem::resize_file(dir / "scan2.bin", 0);
    const io::Dataset dataset = io::OpenDataset(dir.path());
    app::DescribeRun run;
    run.skip_bad = true;
    const auto described = app::DescribeDataset(dataset, core::DescriptorConfig{}, run);
    ASSERT_EQ(described.skipped.size(), 1U);
    EXPECT_NE(described.skipped[0].find("scan 2: " + (dir / "scan2.bin").string() + ": "),
              std::string::npos)
        << described.skipped[0];
}

TEST_F(DetectionRun, ReportsProgressOfEveryScanAndEndsTheStage) {
    app::DetectRequest request = Request("detect", core::Method::kHeight);
    request.config.detection.top_k = 1;
    request.odometry_file = dir_ / "sequence" / "poses_odometry.txt";  // with the submaps stage
    // A few scans a submap: the stage runs as with the default 10 m, at half the cost under the
    // sanitizers, where this test covers verified detection with submaps.
    request.config.detection.verification.reduction.submap_path_m = 4.0;
    std::mutex mutex;
    std::set<std::size_t> seen;
    std::set<std::string> stages;
    request.progress = [&](const std::string& stage, std::size_t done, std::size_t total) {
        const std::lock_guard<std::mutex> lock(mutex);
        EXPECT_EQ(total, dataset_->size());
        stages.insert(stage);
        seen.insert(done);
    };
    app::RunDetect(*dataset_, request);
    EXPECT_EQ(stages, (std::set<std::string>{"describing", "submaps", "verifying"}));
    EXPECT_EQ(seen.size(), dataset_->size());
    EXPECT_EQ(*seen.rbegin(), dataset_->size());
}

TEST_F(DetectionRun, AGapInSecondsWithoutTimesIsAClearError) {
    std::filesystem::create_directories(dir_ / "bare" / "velodyne");
    std::filesystem::copy(dir_ / "sequence" / "velodyne", dir_ / "bare" / "velodyne");
    const io::Dataset bare = io::OpenDataset(dir_ / "bare");
    app::DetectRequest request = Request("detect", core::Method::kHeight);
    request.config.detection.min_gap = {5.0, core::MinGap::Unit::kSeconds};
    EXPECT_THROW(app::RunDetect(bare, request), core::ConfigError);
}

TEST_F(DetectionRun, ARunWithoutAnyCandidateSaysSo) {
    const auto says_no_candidate = [](const app::DetectOutcome& outcome) {
        return std::count_if(outcome.notes.begin(), outcome.notes.end(), [](const auto& note) {
            return test::Contains(note, "no scan had a candidate");
        });
    };
    app::DetectRequest request = Request("detect", core::Method::kHeight);
    request.config.detection.verify = false;
    const app::DetectOutcome usual = app::RunDetect(*dataset_, request);
    EXPECT_EQ(says_no_candidate(usual), 0);
    request.config.detection.min_gap = {1e30, core::MinGap::Unit::kScans};
    request.out = dir_ / "no_candidate";
    const app::DetectOutcome none = app::RunDetect(*dataset_, request);
    ASSERT_EQ(says_no_candidate(none), 1);
    EXPECT_EQ(none.accepted, 0u);
    const auto note = std::find_if(none.notes.begin(), none.notes.end(), [](const auto& text) {
        return test::Contains(text, "no scan had a candidate");
    });
    EXPECT_TRUE(test::Contains(*note, "1e+30 scans")) << *note;
}

// The rows of a CSV file, split at commas (the header first).
std::vector<std::vector<std::string>> CsvCells(const std::filesystem::path& file) {
    std::ifstream in(file);
    std::vector<std::vector<std::string>> rows;
    for (std::string line; std::getline(in, line);) {
        std::vector<std::string> cells(1);
        for (const char c : line) {
            if (c == ',') {
                cells.emplace_back();
            } else {
                cells.back() += c;
            }
        }
        rows.push_back(std::move(cells));
    }
    return rows;
}

// Every row of loops.csv and candidates.csv has the header's column count and ends with path_m,
// the path between its query and match over `poses`; returns the smallest path_m seen.
double ExpectPathColumn(const std::filesystem::path& file,
                        const std::vector<core::StampedPose>& poses) {
    const auto rows = CsvCells(file);
    EXPECT_GT(rows.size(), 1u) << file;
    EXPECT_EQ(rows.front().back(), "path_m") << file;
    double smallest_m = std::numeric_limits<double>::infinity();
    for (std::size_t r = 1; r < rows.size(); ++r) {
        EXPECT_EQ(rows[r].size(), rows.front().size()) << file << " row " << r;
        const std::size_t query = std::stoul(rows[r][0]);
        const std::size_t match = std::stoul(rows[r][rows.front()[1] == "match" ? 1 : 2]);
        const double path_m = std::stod(rows[r].back());
        EXPECT_NEAR(path_m, test::BrutePathM(poses, query, match), 1e-6 * path_m + 1e-9)
            << file << " row " << r;
        smallest_m = std::min(smallest_m, path_m);
    }
    return smallest_m;
}

TEST_F(DetectionRun, PathMIsThePathBetweenQueryAndMatchOnThePosesOrTheOdometry) {
    app::DetectRequest request = Request("poses", core::Method::kRange);
    request.config.detection.verify = false;
    app::RunDetect(*dataset_, request);
    const std::vector<core::StampedPose>& poses = dataset_->poses();
    for (const char* file : {"loops.csv", "candidates.csv"})
        ExpectPathColumn(request.out / file, poses);

    // Odometry twice as far apart, gap in metres: measured on the odometry, outside the gap.
    std::vector<core::StampedPose> odometry = WriteDoubledOdometry();
    request.out = dir_ / "odometry";
    request.odometry_file = dir_ / "odometry.txt";
    request.config.detection.min_gap = {60.0, core::MinGap::Unit::kMetres};
    app::RunDetect(*dataset_, request);
    EXPECT_GT(ExpectPathColumn(request.out / "candidates.csv", odometry), 60.0);
    ExpectPathColumn(request.out / "loops.csv", odometry);

    odometry.pop_back();
    io::WriteTumPoses(dir_ / "short.txt", odometry);
    request.odometry_file = dir_ / "short.txt";
    EXPECT_THROW(app::RunDetect(*dataset_, request), io::ReadError);
}

// evaluate --odometry shortlists as detect --odometry does: the gap and the path rule on the
// odometry's path (here twice the truth's), not the ground truth's.
TEST_F(DetectionRun, EvaluateWithOdometryShortlistsAsDetectWithIt) {
    app::DetectRequest detect = Request("shortlist", core::Method::kRange);
    detect.config.detection.verify = false;
    detect.config.detection.min_gap = {60.0, core::MinGap::Unit::kMetres};
    WriteDoubledOdometry();
    detect.odometry_file = dir_ / "odometry.txt";
    const app::DetectOutcome detected = app::RunDetect(*dataset_, detect);

    const app::EvaluationRequest evaluate = EvaluationLike(detect, "shortlist_evaluate");
    const app::EvaluationOutcome evaluated = app::RunEvaluation(*dataset_, evaluate);
    ASSERT_EQ(evaluated.methods.size(), 1u);
    ASSERT_TRUE(evaluated.methods[0].retrieval);
    const std::vector<pipeline::LoopQuery>& queries = evaluated.methods[0].retrieval->queries;
    ASSERT_EQ(queries.size(), detected.queries.size());
    const std::vector<double>& true_path_m = evaluated.truth.path_m;
    std::size_t within_the_true_gap = 0;
    for (std::size_t q = 0; q < queries.size(); ++q) {
        ASSERT_EQ(queries[q].candidates.size(), detected.queries[q].candidates.size()) << q;
        for (std::size_t k = 0; k < queries[q].candidates.size(); ++k) {
            const std::size_t match = queries[q].candidates[k].index;
            EXPECT_EQ(match, detected.queries[q].candidates[k].index) << q;
            within_the_true_gap += true_path_m[queries[q].query] - true_path_m[match] <= 60.0;
        }
    }
    // Candidates the ground truth's path would have kept out: the case that differs.
    EXPECT_GT(within_the_true_gap, 0u);
}

TEST_F(DetectionRun, AGapInMetresWithoutPosesOrOdometryIsAClearError) {
    std::filesystem::create_directories(dir_ / "bare" / "velodyne");
    std::filesystem::copy(dir_ / "sequence" / "velodyne", dir_ / "bare" / "velodyne");
    const io::Dataset bare = io::OpenDataset(dir_ / "bare");
    app::DetectRequest request = Request("detect", core::Method::kHeight);
    request.config.detection.verify = false;
    request.config.detection.min_gap = {5.0, core::MinGap::Unit::kMetres};
    try {
        app::RunDetect(bare, request);
        ADD_FAILURE() << "no error";
    } catch (const core::ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("--odometry"), std::string::npos) << e.what();
    }
    // Without poses path_m is empty, and the gap in scans still works.
    request.config.detection.min_gap = {10.0, core::MinGap::Unit::kScans};
    app::RunDetect(bare, request);
    const auto rows = CsvCells(request.out / "loops.csv");
    ASSERT_GT(rows.size(), 1u);
    EXPECT_EQ(rows.front().back(), "path_m");
    for (std::size_t r = 1; r < rows.size(); ++r) {
        EXPECT_EQ(rows[r].size(), rows.front().size());
        EXPECT_EQ(rows[r].back(), "");
    }
}

// Some frames of a KITTI sequence with the whole sequence's odometry: each scan takes its frame's
// pose and the path travelled between the frames, not the straight line.
TEST_F(DetectionRun, OdometryOfSomeKittiFramesIsPickedByFrameNumber) {
    const std::filesystem::path odometry_file = dir_ / "sequence" / "poses_odometry.txt";
    const std::vector<core::StampedPose> whole = app::ReadOdometry(odometry_file, "", *dataset_);
    std::filesystem::create_directories(dir_ / "frames" / "velodyne");
    const std::vector<std::size_t> frames = {3, 50, 51, 140};
    for (const std::size_t frame : frames) {
        const std::filesystem::path scan = dataset_->ScanPath(frame);
        std::filesystem::copy_file(scan, dir_ / "frames" / "velodyne" / scan.filename());
    }
    const io::Dataset some = io::OpenDataset(dir_ / "frames");
    const std::vector<core::StampedPose> odometry = app::ReadOdometry(odometry_file, "", some);
    ASSERT_EQ(odometry.size(), frames.size());
    const std::vector<double> whole_path_m = core::CumulativePathM(whole);
    const std::vector<double> path_m = core::CumulativePathM(odometry);
    for (std::size_t i = 0; i < frames.size(); ++i) {
        EXPECT_TRUE(odometry[i].T_world_sensor.isApprox(whole[frames[i]].T_world_sensor));
        EXPECT_NEAR(path_m[i], whole_path_m[frames[i]] - whole_path_m[frames[0]], 1e-9);
    }
    EXPECT_GT(path_m[3] - path_m[2],  // the straight line from frame 51 to 140 is shorter
              (odometry[3].T_world_sensor.translation() - odometry[2].T_world_sensor.translation())
                      .norm() +
                  1.0);
}

// KITTI calib.txt with Tr = T_cam0_velo: the LiDAR x forward, y left, z up seen from the camera
// (z forward, x right, y down), 0.3 m behind it.
std::filesystem::path WriteCalib(const std::filesystem::path& file) {
    std::ofstream(file) << "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n"
                           "Tr: 0 -1 0 0 0 0 -1 0.1 1 0 0 -0.3\n";
    return file;
}

// The odometry written in KITTI's camera frame (P_i = Tr T_i Tr^-1) and read with its calib is
// the LiDAR-frame odometry again; read without, it turns about its y axis, which the run notes.
TEST_F(DetectionRun, OdometryInKittisCameraFrameIsConvertedByItsCalib) {
    const std::filesystem::path lidar_file = dir_ / "sequence" / "poses_odometry.txt";
    const std::vector<core::StampedPose> lidar = app::ReadOdometry(lidar_file, "", *dataset_);
    const std::filesystem::path calib = WriteCalib(dir_ / "calib_odometry.txt");
    const core::Transform Tr = io::ReadKittiCalibTr(calib);
    std::vector<core::StampedPose> camera = lidar;
    for (core::StampedPose& pose : camera)
        pose.T_world_sensor = Tr * pose.T_world_sensor * Tr.inverse();
    const std::filesystem::path camera_file = dir_ / "odometry_camera.txt";
    io::WriteKittiPoses(camera_file, camera);

    const std::vector<core::StampedPose> converted = app::ReadOdometry(
        camera_file, "", *dataset_, std::numeric_limits<double>::infinity(), calib);
    ASSERT_EQ(converted.size(), lidar.size());
    for (std::size_t i = 0; i < lidar.size(); ++i)
        EXPECT_TRUE(converted[i].T_world_sensor.isApprox(lidar[i].T_world_sensor, 1e-9)) << i;
    EXPECT_EQ(app::CameraFrameNote(converted), "");
    EXPECT_EQ(app::CameraFrameNote(lidar), "");
    EXPECT_NE(app::CameraFrameNote(app::ReadOdometry(camera_file, "", *dataset_)), "")
        << "the simulated drive turns: the camera frame must show";

    app::DetectRequest request;
    request.config.detection.verify = false;
    request.out = dir_ / "camera";
    request.odometry_file = camera_file;
    const auto calib_notes = [](const std::vector<std::string>& notes) {
        return std::count_if(notes.begin(), notes.end(), [](const std::string& note) {
            return note.find("--odometry-calib") != std::string::npos;
        });
    };
    EXPECT_EQ(calib_notes(app::RunDetect(*dataset_, request).notes), 1);
    const std::filesystem::path map = request.out / "database.lldb";
    request.out = dir_ / "camera_localised";  // localising against a map says so too
    EXPECT_EQ(calib_notes(app::RunLocalise(*dataset_, app::LoadMap(map), request).notes), 1);
}

// A calib converts KITTI poses from a file: with a TUM file, a bag's topic or no odometry it is
// a ConfigError, never ignored.
TEST_F(DetectionRun, AnOdometryCalibWithoutKittiPosesIsAConfigError) {
    const std::filesystem::path calib = WriteCalib(dir_ / "calib_odometry.txt");
    const std::filesystem::path tum = dir_ / "odometry.tum";
    io::WriteTumPoses(tum,
                      app::ReadOdometry(dir_ / "sequence" / "poses_odometry.txt", "", *dataset_));
    const double any_step = std::numeric_limits<double>::infinity();
    EXPECT_THROW(app::ReadOdometry(tum, "", *dataset_, any_step, calib), core::ConfigError);
    EXPECT_THROW(app::ReadOdometry("", "/odom", *dataset_, any_step, calib), core::ConfigError);
    EXPECT_THROW(app::ReadOdometry("", "", *dataset_, any_step, calib), core::ConfigError);
    EXPECT_THROW(app::ReadOdometryIfGiven("", "", *dataset_, any_step, calib), core::ConfigError);
    EXPECT_TRUE(app::ReadOdometryIfGiven("", "", *dataset_, any_step, {}).empty());
    app::DetectRequest request;
    request.out = dir_ / "calib_alone";
    request.odometry_calib = calib;
    EXPECT_THROW(app::RunDetect(*dataset_, request), core::ConfigError);
}

// With poses every stored scan is its submap, placed by them; without, each scan is alone, the
// run says so, and config.yaml and database.scans record it.
TEST_F(DetectionRun, SubmapsInOrderReadEachScanOnceAndEqualEachSubmapAlone) {
    std::vector<core::StampedPose> poses =
        app::ReadOdometry(dir_ / "sequence" / "poses_odometry.txt", "", *dataset_);
    poses.resize(40);  // two blocks of centres: 0-31 and 32-39
    registration::ScanReductionConfig reduction;
    reduction.submap_path_m = 6.0;
    std::vector<std::atomic<int>> reads(poses.size());
    const auto load = [&](std::size_t k) {
        ++reads.at(k);
        return dataset_->LoadScan(k);
    };
    const auto wanted = [](std::size_t i) { return i != 5 && i != 35; };
    std::vector<std::optional<registration::PreparedScan>> submaps(poses.size());
    app::PrepareSubmapsInOrder(poses, reduction, load, wanted,
                               [&](std::size_t i, registration::PreparedScan submap, double) {
                                   submaps.at(i) = std::move(submap);
                               });
    const auto load_again = [this](std::size_t k) { return dataset_->LoadScan(k); };
    const std::vector<double> path_m = registration::SubmapPathM(poses);
    std::size_t largest_submap = 0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
        EXPECT_EQ(reads[i], 1) << i;  // 5 and 35 as their neighbours' members
        ASSERT_EQ(submaps[i].has_value(), wanted(i)) << i;
        if (!wanted(i)) continue;
        const registration::PreparedScan expected =
            registration::PrepareSubmap(i, poses, path_m, load_again, reduction);
        EXPECT_EQ(submaps[i]->structure->points(), expected.structure->points()) << i;
        EXPECT_EQ(submaps[i]->structure->normals(), expected.structure->normals()) << i;
        EXPECT_EQ(submaps[i]->ground->points(), expected.ground->points()) << i;
        EXPECT_EQ(submaps[i]->structure_distinctive, expected.structure_distinctive) << i;
        largest_submap = std::max(largest_submap,
                                  registration::SubmapMembers(path_m, i, {6.0, 30, false}).size());
    }
    EXPECT_GE(largest_submap, 3u);  // the windows reach across the blocks' ends
}

// Scans whose median fills the structure cap alone are verified alone: the median of the
// readable scans, against a brute-force median, at the cap and one point over it.
TEST_F(DetectionRun, ScansThatFillTheStructureCapAloneAreVerifiedAlone) {
    const std::filesystem::path folder = dir_ / "nine";
    std::filesystem::create_directories(folder / "velodyne");
    std::vector<std::size_t> structure;
    registration::ScanReductionConfig reduction;
    for (std::size_t i = 0; i < 9; ++i) {
        const std::string name = std::string("00000") + std::to_string(i) + ".bin";
        std::filesystem::copy_file(dir_ / "sequence" / "velodyne" / name,
                                   folder / "velodyne" / name);
        structure.push_back(
            registration::PrepareScan(dataset_->LoadScan(i), reduction).structure->size());
    }
    // Unreadable scans are left out (counted as empty, they would lower the median).
    test::WriteFile(folder / "velodyne" / "000009.bin", "corrupt");
    test::WriteFile(folder / "velodyne" / "000010.bin", "corrupt");
    const io::Dataset nine = io::OpenDataset(folder);
    ASSERT_EQ(nine.size(), 11u);
    std::sort(structure.begin(), structure.end());
    const std::size_t median = structure[4];
    ASSERT_LT(median, static_cast<std::size_t>(reduction.max_structure_points));  // sparse
    reduction.max_structure_points = static_cast<int>(median);
    EXPECT_TRUE(app::ScansFillTheStructureCap(nine, reduction));
    reduction.max_structure_points = static_cast<int>(median + 1);
    EXPECT_FALSE(app::ScansFillTheStructureCap(nine, reduction));
}

// The verified loops of an evaluation's one method are detect's, at the same poses, and some.
void ExpectTheSameLoops(const app::EvaluationOutcome& evaluated,
                        const app::DetectOutcome& detected) {
    ASSERT_EQ(evaluated.methods.size(), 1u);
    ASSERT_TRUE(evaluated.methods[0].retrieval);
    const std::vector<pipeline::LoopQuery>& queries = evaluated.methods[0].retrieval->queries;
    ASSERT_EQ(queries.size(), detected.queries.size());
    std::size_t loops = 0;
    for (std::size_t q = 0; q < queries.size(); ++q) {
        ASSERT_EQ(queries[q].loop(), detected.queries[q].loop()) << q;
        if (!queries[q].loop()) continue;
        ++loops;
        const auto& verdict = queries[q].verifications[*queries[q].loop()];
        const auto& detected_verdict = detected.queries[q].verifications[*queries[q].loop()];
        EXPECT_EQ(verdict.T_match_query.matrix(), detected_verdict.T_match_query.matrix()) << q;
    }
    EXPECT_GT(loops, 0u);
}

// evaluate without odometry verifies as detect without it: submaps placed by the neighbours.
TEST_F(DetectionRun, EvaluateWithoutOdometryVerifiesAsDetectWithoutIt) {
    LIDARLOOP_RELEASE_SUITE_ONLY();  // a verified run with submaps, and an evaluation
    app::DetectRequest detect = Request("detect", core::Method::kRange);
    detect.config.detection.top_k = 3;
    const app::DetectOutcome detected = app::RunDetect(*dataset_, detect);
    const app::EvaluationOutcome evaluated =
        app::RunEvaluation(*dataset_, EvaluationLike(detect, "evaluate"));
    ExpectTheSameLoops(evaluated, detected);
}

// The note on an unread poses_odometry.txt: none when the run does not verify, has an
// odometry, or opened the dataset with that file as its poses (then it is read).
TEST_F(DetectionRun, TheUnreadOdometryNoteIsGivenOnlyWhenTheFileIsUnread) {
    const std::filesystem::path file = dir_ / "sequence" / "poses_odometry.txt";
    EXPECT_TRUE(test::Contains(app::UnusedOdometryNote(*dataset_, {}, true), kUnusedOdometry));
    EXPECT_EQ(app::UnusedOdometryNote(*dataset_, {}, false), "");  // a run that does not verify
    EXPECT_EQ(app::UnusedOdometryNote(*dataset_, dataset_->poses(), true), "");
    io::DatasetOptions as_poses;
    as_poses.poses_file = file;
    EXPECT_EQ(app::UnusedOdometryNote(io::OpenDataset(dir_ / "sequence", as_poses), {}, true), "");
}

// A run on scans that fill the structure cap alone says so, and config.yaml and database.scans
// record no submaps; evaluate verifies them alone as detect does.
TEST_F(DetectionRun, ARunOnScansThatFillTheStructureCapSaysItVerifiesThemAlone) {
    LIDARLOOP_RELEASE_SUITE_ONLY();  // verified runs; the rule's median runs in both suites
    registration::ScanReductionConfig reduction;
    std::size_t fewest = std::numeric_limits<std::size_t>::max();
    for (std::size_t i = 0; i < dataset_->size(); ++i) {
        fewest = std::min(
            fewest, registration::PrepareScan(dataset_->LoadScan(i), reduction).structure->size());
    }
    app::DetectRequest request = Request("dense", core::Method::kRange);
    request.config.detection.top_k = 1;
    request.config.detection.verification.reduction.max_structure_points = static_cast<int>(fewest);
    const app::DetectOutcome outcome = app::RunDetect(*dataset_, request);
    ASSERT_NO_FATAL_FAILURE(
        ExpectNotesSaying(outcome.notes, {kUnusedOdometry, "fills the structure cap alone"}));
    EXPECT_EQ(WrittenSubmapPathM(request.out), 0.0);
    EXPECT_EQ(io::LoadPreparedScans(request.out / "database.scans").reduction.submap_path_m, 0.0);

    const app::EvaluationRequest evaluate = EvaluationLike(request, "evaluate");
    const app::EvaluationOutcome evaluated = app::RunEvaluation(*dataset_, evaluate);
    ASSERT_NO_FATAL_FAILURE(
        ExpectNotesSaying(evaluated.notes, {kUnusedOdometry, "fills the structure cap alone"}));
    EXPECT_EQ(WrittenSubmapPathM(evaluate.out), 0.0);
    ExpectTheSameLoops(evaluated, outcome);
}

// evaluate --odometry verifies as detect --odometry does: the same submaps, the same gate.
TEST_F(DetectionRun, EvaluateWithOdometryVerifiesAsDetectWithIt) {
    LIDARLOOP_RELEASE_SUITE_ONLY();  // two verified runs with submaps, and an evaluation
    app::DetectRequest detect = Request("detect", core::Method::kRange);
    detect.config.detection.top_k = 1;
    detect.odometry_file = dir_ / "sequence" / "poses_odometry.txt";
    const app::DetectOutcome detected = app::RunDetect(*dataset_, detect);

    app::EvaluationRequest evaluate = EvaluationLike(detect, "evaluate");
    const app::EvaluationOutcome evaluated = app::RunEvaluation(*dataset_, evaluate);
    EXPECT_TRUE(evaluated.notes.empty()) << evaluated.notes.front();
    EXPECT_EQ(WrittenSubmapPathM(evaluate.out),
              detect.config.detection.verification.reduction.submap_path_m);
    ExpectTheSameLoops(evaluated, detected);

    // The ground truth given as odometry is said to flatter the figures.
    evaluate.odometry_file = dir_ / "sequence" / "poses.txt";
    evaluate.out = dir_ / "evaluate_truth";
    const app::EvaluationOutcome flattered = app::RunEvaluation(*dataset_, evaluate);
    ASSERT_NO_FATAL_FAILURE(ExpectOneNoteSaying(flattered.notes, "ground truth"));

    // Without odometry the scans' registrations to their neighbours place the submaps, as in
    // detect, and a note says so.
    evaluate.odometry_file.clear();
    evaluate.out = dir_ / "evaluate_neighbours";
    const app::EvaluationOutcome by_neighbours = app::RunEvaluation(*dataset_, evaluate);
    ASSERT_NO_FATAL_FAILURE(ExpectNotesSaying(by_neighbours.notes,
                                              {kUnusedOdometry, "registration to the one before"}));
    EXPECT_EQ(WrittenSubmapPathM(evaluate.out),
              detect.config.detection.verification.reduction.submap_path_m);
}

TEST_F(DetectionRun, ScansAreSubmapsWhenTheOdometryIsKnown) {
    // Two verified runs; submaps run under the sanitizers in SubmapsInOrderReadEachScanOnce...
    // and ReportsProgressOfEveryScanAndEndsTheStage.
    LIDARLOOP_RELEASE_SUITE_ONLY();
    app::DetectRequest request = Request("submaps", core::Method::kRange);
    request.config.detection.top_k = 1;
    request.odometry_file = dir_ / "sequence" / "poses_odometry.txt";
    const registration::ScanReductionConfig& reduction =
        request.config.detection.verification.reduction;
    const app::DetectOutcome outcome = app::RunDetect(*dataset_, request);
    EXPECT_TRUE(outcome.notes.empty());
    const io::StoredPreparedScans stored = io::LoadPreparedScans(request.out / "database.scans");
    EXPECT_EQ(stored.reduction.submap_path_m, reduction.submap_path_m);
    EXPECT_EQ(stored.reduction.submap_max_points, reduction.submap_max_points);
    const std::vector<core::StampedPose> poses =
        app::ReadOdometry(request.odometry_file, "", *dataset_);
    const auto load = [this](std::size_t k) { return dataset_->LoadScan(k); };
    for (const std::size_t i : {std::size_t{0}, std::size_t{77}, poses.size() - 1}) {
        const registration::PreparedScan expected =
            registration::CompactPreparedScan(
                registration::PrepareSubmap(i, poses, registration::SubmapPathM(poses), load,
                                            reduction))
                .Expand();
        const registration::PreparedScan kept = stored.scans.at(i);
        EXPECT_EQ(kept.structure->size(), expected.structure->size()) << i;
        EXPECT_EQ(kept.usable_points, expected.usable_points) << i;
    }
    EXPECT_GT(stored.scans.at(77).usable_points,
              registration::PrepareScan(dataset_->LoadScan(77), reduction).usable_points);

    // Without odometry each scan's registration to the one before places the submaps, also
    // where the dataset has poses: in KITTI layout they are the ground truth the loops are
    // scored against. Every pair is registered once, and the submap holds its neighbours.
    request.odometry_file.clear();
    request.out = dir_ / "by_neighbours";
    const app::DetectOutcome by_neighbours = app::RunDetect(*dataset_, request);
    ASSERT_TRUE(dataset_->HasPoses());
    ASSERT_NO_FATAL_FAILURE(ExpectNotesSaying(by_neighbours.notes,
                                              {kUnusedOdometry, "registration to the one before"}));
    const io::StoredPreparedScans chained = io::LoadPreparedScans(request.out / "database.scans");
    EXPECT_EQ(chained.reduction.submap_path_m, reduction.submap_path_m);
    EXPECT_EQ(WrittenSubmapPathM(request.out), reduction.submap_path_m);
    EXPECT_GT(chained.scans.at(77).usable_points,
              registration::PrepareScan(dataset_->LoadScan(77), reduction).usable_points);

    // With no submaps asked for, each scan is verified alone.
    request.config.detection.verification.reduction.submap_path_m = 0.0;
    request.out = dir_ / "alone";
    const app::DetectOutcome alone = app::RunDetect(*dataset_, request);
    ASSERT_NO_FATAL_FAILURE(ExpectOneNoteSaying(alone.notes, kUnusedOdometry));
    EXPECT_EQ(io::LoadPreparedScans(request.out / "database.scans").scans.at(77).usable_points,
              registration::PrepareScan(dataset_->LoadScan(77), reduction).usable_points);
}

// detect stopping at the first loop (the default) with the odometry (submaps, the gate): each
// query's loop is the first candidate in rank order that registering every one accepts and the
// gate keeps, with the same verdicts up to it; the same scans are closed, registering fewer pairs.
TEST_F(DetectionRun, StoppingAtTheFirstLoopClosesTheSameScansRegisteringFewerPairs) {
    LIDARLOOP_RELEASE_SUITE_ONLY();  // two verified runs; StopAtFirstLoop covers the sanitizers
    app::DetectRequest every = Request("every", core::Method::kRange);
    every.config.detection.top_k = 5;
    every.config.detection.stop_at_first_loop = false;
    every.odometry_file = dir_ / "sequence" / "poses_odometry.txt";
    app::DetectRequest first = every;
    first.out = dir_ / "first";
    first.config.detection.stop_at_first_loop = true;
    const app::DetectOutcome all = app::RunDetect(*dataset_, every);
    const app::DetectOutcome stopped = app::RunDetect(*dataset_, first);
    ASSERT_EQ(all.queries.size(), stopped.queries.size());
    std::size_t registered_all = 0, registered_stopped = 0;
    const auto registered = [](const registration::Verification& v) {
        return v.reason != registration::RejectReason::kNotNeeded &&
               v.reason != registration::RejectReason::kPruned;
    };
    for (std::size_t i = 0; i < all.queries.size(); ++i) {
        const pipeline::LoopQuery& a = all.queries[i];
        const pipeline::LoopQuery& s = stopped.queries[i];
        ASSERT_EQ(s.verifications.size(), a.verifications.size()) << i;
        const auto loop = std::find_if(a.verifications.begin(), a.verifications.end(),
                                       [](const auto& v) { return v.accepted; });
        const std::size_t until = static_cast<std::size_t>(loop - a.verifications.begin());
        for (std::size_t c = 0; c < a.verifications.size(); ++c) {
            if (c <= until) {
                EXPECT_EQ(s.verifications[c].reason, a.verifications[c].reason) << i << " " << c;
                EXPECT_TRUE(
                    s.verifications[c].T_match_query.isApprox(a.verifications[c].T_match_query))
                    << i << " " << c;
            } else {
                EXPECT_EQ(s.verifications[c].reason, registration::RejectReason::kNotNeeded);
            }
            registered_all += registered(a.verifications[c]) ? 1 : 0;
            registered_stopped += registered(s.verifications[c]) ? 1 : 0;
        }
        EXPECT_EQ(s.accepted, a.accepted) << i;
        if (s.accepted) {
            EXPECT_EQ(*s.loop(), until) << i;
        }
    }
    EXPECT_EQ(stopped.accepted, all.accepted);
    EXPECT_GT(all.accepted, 10u);  // the sequence revisits: there are loops to stop at
    EXPECT_LT(registered_stopped, registered_all);
    std::ifstream candidates(first.out / "candidates.csv");
    const std::string text((std::istreambuf_iterator<char>(candidates)), {});
    EXPECT_TRUE(test::Contains(text, ",not_needed,"));
    EXPECT_TRUE(io::LoadConfigYaml(first.out / "config.yaml").detection.stop_at_first_loop);
}

// optimise --loops reads a verified loops.csv with path_m, and one written before it existed.
TEST_F(DetectionRun, TheLoopsReaderTakesFilesWithAndWithoutPathM) {
    // A verified run; the reader is fuzzed and replayed under the sanitizers (tests/fuzz), and
    // detection's verification runs there in ReportsProgressOfEveryScanAndEndsTheStage.
    LIDARLOOP_RELEASE_SUITE_ONLY();
    app::DetectRequest request = Request("verified", core::Method::kRange);
    request.config.detection.top_k = 1;
    const app::DetectOutcome outcome = app::RunDetect(*dataset_, request);
    ASSERT_GT(outcome.accepted, 0u);
    const auto with = io::ReadLoopsCsv(request.out / "loops.csv", dataset_->size());
    EXPECT_EQ(with.size(), outcome.accepted);
    std::string without;
    for (const auto& row : CsvCells(request.out / "loops.csv")) {
        for (std::size_t c = 0; c + 1 < row.size(); ++c) without += (c ? "," : "") + row[c];
        without += "\n";
    }
    test::WriteFile(dir_ / "old_loops.csv", without);
    const auto old = io::ReadLoopsCsv(dir_ / "old_loops.csv", dataset_->size());
    ASSERT_EQ(old.size(), with.size());
    for (std::size_t k = 0; k < old.size(); ++k) {
        EXPECT_EQ(old[k].loop.query, with[k].loop.query);
        EXPECT_EQ(old[k].loop.match, with[k].loop.match);
        EXPECT_TRUE(old[k].loop.T_match_query.isApprox(with[k].loop.T_match_query));
    }
}

}  // namespace
}  // namespace lidarloop

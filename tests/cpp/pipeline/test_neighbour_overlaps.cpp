#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include "lidarloop/pipeline/candidate_verification.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/pipeline/neighbour_overlaps.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"
#include "lidarloop/registration/submap.hpp"
#include "pipeline/detect_both_ways.hpp"
#include "registration/registration_test_utils.hpp"

namespace lidarloop::pipeline {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
using registration::RejectReason;

// A place's mirror image (y -> -y): the same kinds of surfaces, in an arrangement no rigid motion
// of the place gives.
core::PointCloud Mirrored(core::PointCloud cloud) {
    for (auto& point : cloud) point.y() = -point.y();
    return cloud;
}

// Place 1 seen twice 1 m apart (scans 0, 1), place 2 twice (scans 2, 3), place 1 again turned
// by 170 degrees (scan 4): scans 0, 1 and 4 register to each other, 3 and 4 do not.
std::vector<core::PointCloud> TwoPlacesAndARevisit() {
    const core::PointCloud first = test::SyntheticPlace(1);
    const core::PointCloud second = Mirrored(test::SyntheticPlace(2));
    return {first, test::Transformed(first, test::PlanarTransform(-1.0, 0.0, 0.0)), second,
            test::Transformed(second, test::PlanarTransform(-1.0, 0.0, 0.0)),
            test::Transformed(first, test::PlanarTransform(1.0, -1.5, 170.0))};
}

// Two walls along a straight corridor 8 m wide and its floor: nothing pins a step along it.
core::PointCloud Corridor() {
    core::PointCloud corridor;
    for (double x = -40.0; x <= 40.0; x += 0.25) {
        for (double z = -1.7; z <= 3.0; z += 0.25) {
            corridor.emplace_back(x, 4.0, z);
            corridor.emplace_back(x, -4.0, z);
        }
        for (double y = -4.0; y <= 4.0; y += 0.5) corridor.emplace_back(x, y, -1.7);
    }
    return corridor;
}

std::vector<registration::CompactPreparedScan> Prepared(const std::vector<core::PointCloud>& scans,
                                                        const DetectorConfig& detector) {
    std::vector<registration::CompactPreparedScan> prepared;
    for (const auto& scan : scans)
        prepared.emplace_back(registration::PrepareScan(scan, detector.verification.reduction));
    return prepared;
}

// A corridor and the same corridor seen 1 m further along it and 0.3 m to the side.
std::vector<registration::CompactPreparedScan> CorridorStep(const DetectorConfig& detector) {
    const core::PointCloud corridor = Corridor();
    return Prepared({corridor, test::Transformed(corridor, test::PlanarTransform(-1.0, 0.3, 0.0))},
                    detector);
}

// The neighbour registrations of `prepared`, which must outlive them.
NeighbourOverlaps NeighboursOf(const std::vector<registration::CompactPreparedScan>& prepared,
                               const DetectorConfig& detector) {
    return NeighbourOverlaps([&prepared](std::size_t i) { return prepared.at(i).Expand(); },
                             [&prepared] { return prepared.size(); }, detector.verification);
}

DetectorConfig Verifying(double min_neighbour_overlap_ratio) {
    DetectorConfig detector;
    detector.min_gap = {2.0, core::MinGap::Unit::kScans};
    detector.min_path_m = 0.0;
    detector.top_k = 2;
    detector.verification.acceptance.min_neighbour_overlap_ratio = min_neighbour_overlap_ratio;
    return detector;
}

// A query whose candidates were all registered and accepted with these distinctive overlaps.
LoopQuery AcceptedQuery(std::size_t query, const std::vector<std::size_t>& matches,
                        const std::vector<double>& distinctive_overlaps) {
    LoopQuery result;
    result.query = query;
    for (std::size_t c = 0; c < matches.size(); ++c) {
        result.candidates.push_back({matches[c], static_cast<double>(c)});
        registration::Verification verdict;
        verdict.accepted = true;
        verdict.overlap.query_fraction = verdict.overlap.match_fraction = 0.9;
        verdict.overlap.query_distinctive_fraction = distinctive_overlaps[c];
        verdict.overlap.match_distinctive_fraction = 0.9;
        result.verifications.push_back(verdict);
    }
    result.accepted = true;
    return result;
}

TEST(NeighbourOverlaps, RegistersEachScanToTheOneBeforeOnce) {
    const DetectorConfig detector = Verifying(0.5);
    const auto prepared = Prepared(TwoPlacesAndARevisit(), detector);
    std::atomic<int> expanded{0};
    NeighbourOverlaps neighbours(
        [&](std::size_t i) {
            ++expanded;
            return prepared[i].Expand();
        },
        [&] { return prepared.size(); }, detector.verification);
    // Scan 1 is scan 0 moved 1 m: nearly every distinctive point overlaps; scan 0 shares its pair.
    const double first_place = neighbours.Of(1);
    EXPECT_GT(first_place, 0.8);
    EXPECT_EQ(neighbours.Of(0), first_place);
    EXPECT_GT(neighbours.Of(3), 0.8);
    EXPECT_TRUE(std::isnan(neighbours.Of(2))) << "place 2 is not place 1: no reference";
    EXPECT_TRUE(std::isnan(neighbours.Of(4)));
    EXPECT_EQ(neighbours.registered(), 4U);
    const int expansions = expanded;
    for (std::size_t i = 0; i < prepared.size(); ++i) neighbours.Of(i);
    EXPECT_EQ(expanded, expansions) << "each pair is registered once";
    EXPECT_EQ(neighbours.registered(), 4U);
    // The same registrations give the steps: scan 1 sits 1 m ahead of scan 0 (its points lie 1 m
    // further back), scan 3 1 m ahead of scan 2.
    for (const std::size_t later : {1U, 3U}) {
        const std::optional<core::Transform> step = neighbours.StepOf(later);
        ASSERT_TRUE(step.has_value()) << later;
        EXPECT_LT((step->translation() - Eigen::Vector3d(1.0, 0.0, 0.0)).norm(), 0.05) << later;
        EXPECT_LT(Eigen::AngleAxisd(step->linear()).angle(), 0.01) << later;
    }
    EXPECT_FALSE(neighbours.StepOf(0).has_value()) << "scan 0 has no scan before it";
    EXPECT_FALSE(neighbours.StepOf(5).has_value()) << "not there yet";
    EXPECT_EQ(expanded, expansions) << "StepOf reads the pairs Of registered";
}

// Two walls along a straight corridor: a step along it is not pinned, so the pair is rejected
// (no reference), but ICP registered it, and its heading and sideways offset are the corridor's.
TEST(NeighbourOverlaps, ARegisteredPairGivesItsStepWhateverItsVerdict) {
    const DetectorConfig detector = Verifying(0.5);
    const auto prepared = CorridorStep(detector);
    NeighbourOverlaps neighbours = NeighboursOf(prepared, detector);
    EXPECT_TRUE(std::isnan(neighbours.Of(1))) << "a corridor does not pin a step along it";
    const std::optional<core::Transform> step = neighbours.StepOf(1);
    ASSERT_TRUE(step.has_value());
    EXPECT_NEAR(step->translation().y(), -0.3, 0.05);
    EXPECT_LT(Eigen::AngleAxisd(step->linear()).angle(), 0.01);
}

// Without odometry the accepted steps place the submaps: scans 0-1 and 2-3 are two pieces (1 m
// steps), scan 4 a third; each piece starts at the identity, and the path jumps by twice the
// window and a metre between pieces, so no submap joins two of them and no pair of one piece
// within twice the window may close.
TEST(PosesFromNeighbours, ChainsTheAcceptedStepsIntoPiecesNoWindowJoins) {
    const DetectorConfig detector = Verifying(0.5);
    const auto prepared = Prepared(TwoPlacesAndARevisit(), detector);
    NeighbourOverlaps neighbours = NeighboursOf(prepared, detector);
    const double window_m = 10.0;
    const std::vector<core::StampedPose> poses =
        PosesFromNeighbours(neighbours, prepared.size(), window_m, Execution::kParallel);
    ASSERT_EQ(poses.size(), prepared.size());
    EXPECT_EQ(neighbours.registered(), 4U) << "every pair, once";
    const std::vector<double> expected_path_m{0.0, 1.0, 22.0, 23.0, 44.0};
    for (std::size_t i = 0; i < poses.size(); ++i) {
        ASSERT_TRUE(poses[i].path_m.has_value()) << i;
        EXPECT_NEAR(*poses[i].path_m, expected_path_m[i], 0.05) << i;
    }
    for (const std::size_t start : {0U, 2U, 4U}) {
        EXPECT_TRUE(poses[start].T_world_sensor.isApprox(core::Transform::Identity())) << start;
    }
    for (const std::size_t later : {1U, 3U}) {
        EXPECT_LT(
            (poses[later].T_world_sensor.translation() - Eigen::Vector3d(1.0, 0.0, 0.0)).norm(),
            0.05)
            << later;
    }
    const std::vector<double> path_m = registration::SubmapPathM(poses);
    const registration::SubmapWindow window{window_m, 30, false};
    EXPECT_EQ(registration::SubmapMembers(path_m, 1, window), (std::vector<std::size_t>{0, 1}));
    EXPECT_EQ(registration::SubmapMembers(path_m, 2, window), (std::vector<std::size_t>{2, 3}));
    EXPECT_EQ(registration::SubmapMembers(path_m, 4, window), (std::vector<std::size_t>{4}));

    const LoopCheck apart = SubmapsApart(poses, window_m);
    EXPECT_FALSE(apart.MayClose(1, 0, 10.0)) << "one piece, 1 m apart";
    EXPECT_FALSE(apart.MayClose(3, 2, 10.0));
    EXPECT_TRUE(apart.MayClose(2, 1, 10.0)) << "two pieces";
    EXPECT_TRUE(apart.MayClose(4, 0, 10.0));
    EXPECT_FALSE(static_cast<bool>(apart)) << "it rejects no verified loop";
}

// A pair ICP registered but verification did not accept (a corridor's step along it) places
// nothing: the next scan starts a piece.
TEST(PosesFromNeighbours, AStepNotAcceptedStartsAPiece) {
    const DetectorConfig detector = Verifying(0.5);
    const auto prepared = CorridorStep(detector);
    NeighbourOverlaps neighbours = NeighboursOf(prepared, detector);
    const std::vector<core::StampedPose> poses =
        PosesFromNeighbours(neighbours, prepared.size(), 10.0, Execution::kSerial);
    ASSERT_TRUE(neighbours.StepOf(1).has_value()) << "registered";
    EXPECT_TRUE(poses[1].T_world_sensor.isApprox(core::Transform::Identity()));
    EXPECT_DOUBLE_EQ(*poses[1].path_m, 21.0);
}

// A chain of steps runs back to the first scan without a step: a scan without structure (scan 2)
// breaks it on both sides. Each step is registered once, however often the chain is asked for.
TEST(NeighbourOverlaps, AChainStartsWhereAStepIsMissing) {
    const DetectorConfig detector = Verifying(0.5);
    const auto corridor = CorridorStep(detector);
    const std::vector<registration::CompactPreparedScan> prepared = {
        corridor[0], corridor[1], registration::CompactPreparedScan{}, corridor[0], corridor[1]};
    NeighbourOverlaps neighbours = NeighboursOf(prepared, detector);
    EXPECT_EQ(neighbours.ChainStart(4), 3U);
    EXPECT_EQ(neighbours.ChainStart(1), 0U);
    EXPECT_EQ(neighbours.registered(), 3U) << "steps 4, 3 and 1: the walks stop at a break";
    const std::vector<std::size_t> expected = {0, 0, 2, 3, 3};
    for (std::size_t scan = 0; scan < prepared.size(); ++scan)
        EXPECT_EQ(neighbours.ChainStart(scan), expected[scan]) << scan;
    EXPECT_EQ(neighbours.registered(), 4U);
    EXPECT_EQ(neighbours.ChainStart(7), 7U) << "not there yet";
}

// The motion rule judges a pair where one chain joins match to query, and only where the rule is
// on, the scans alone judge (no given check) and the chains are known.
TEST(JudgeOf, TheMotionJudgesThePairsAChainJoins) {
    const auto reference_of = [](std::size_t) { return 1.0; };
    const StepOf step_of = [](std::size_t) { return core::Transform::Identity(); };
    const ChainStartOf chain_start_of = [](std::size_t scan) {
        return std::vector<std::size_t>{0, 0, 0, 3, 3, 3}.at(scan);
    };
    registration::VerificationConfig config;
    const LoopCheck judge = JudgeOf({}, reference_of, step_of, config, chain_start_of);
    EXPECT_TRUE(judge.MotionJudges(2, 0));
    EXPECT_TRUE(judge.MotionJudges(5, 3));
    EXPECT_FALSE(judge.MotionJudges(5, 2)) << "the chain breaks at scan 3";
    EXPECT_FALSE(judge.MotionJudges(0, 2)) << "a match after its query";
    EXPECT_FALSE(judge.MotionJudges(3, 3));
    EXPECT_FALSE(JudgeOf({}, reference_of, step_of, config).MotionJudges(2, 0));
    EXPECT_FALSE(JudgeOf({}, reference_of, {}, config, chain_start_of).MotionJudges(2, 0));
    LoopCheck odometry;
    odometry.reject = [](LoopQuery& /*unused*/) {};
    EXPECT_FALSE(
        JudgeOf(odometry, reference_of, step_of, config, chain_start_of).MotionJudges(2, 0));
    config.acceptance.motion_max_turn_deg = 30.0;  // a chain that turns more goes unjudged
    EXPECT_FALSE(JudgeOf({}, reference_of, step_of, config, chain_start_of).MotionJudges(2, 0));
    config.acceptance.motion_max_turn_deg = 0.0;
    EXPECT_FALSE(JudgeOf({}, reference_of, step_of, config, chain_start_of).MotionJudges(2, 0));
}

// VerifyQueries asks from several threads, in any order, while the cache grows: every thread
// must read the pairs one thread alone reads, and each pair is kept once.
TEST(NeighbourOverlaps, ThreadsAskingInAnyOrderReadWhatOneThreadReads) {
    const core::PointCloud place = test::SyntheticPlace(3);
    std::vector<core::PointCloud> scans;
    for (int i = 0; i < 24; ++i)
        scans.push_back(test::Transformed(place, test::PlanarTransform(-0.7 * i, 0.0, 2.0 * i)));
    const DetectorConfig detector = Verifying(0.5);
    const auto prepared = Prepared(scans, detector);
    const auto make = [&] {
        return NeighbourOverlaps([&](std::size_t i) { return prepared.at(i).Expand(); },
                                 [&] { return prepared.size(); }, detector.verification);
    };
    NeighbourOverlaps alone = make();
    std::vector<std::size_t> order(scans.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::shuffle(order.begin(), order.end(), std::mt19937(7));
    std::reverse(order.begin(), order.begin() + 8);  // some high indices first: the cache grows
    NeighbourOverlaps shared = make();
    std::vector<std::optional<core::Transform>> steps(scans.size());
    std::vector<double> overlaps(scans.size());
    tbb::parallel_for(std::size_t{0}, order.size(), [&](std::size_t k) {
        steps[order[k]] = shared.StepOf(order[k]);
        overlaps[order[k]] = shared.Of(order[k]);
    });
    for (std::size_t i = 0; i < scans.size(); ++i) {
        const std::optional<core::Transform> expected = alone.StepOf(i);
        ASSERT_EQ(steps[i].has_value(), expected.has_value()) << i;
        if (expected) {
            EXPECT_TRUE(steps[i]->isApprox(*expected, 1e-12)) << i;
        }
        const double overlap = alone.Of(i);
        EXPECT_TRUE(overlaps[i] == overlap || (std::isnan(overlaps[i]) && std::isnan(overlap)))
            << i;
    }
    EXPECT_EQ(shared.registered(), alone.registered());
}

TEST(NeighbourOverlaps, AScanWithoutItsNeighbourYetHasNoReferenceAndGetsOneLater) {
    const DetectorConfig detector = Verifying(0.5);
    const auto prepared = Prepared(TwoPlacesAndARevisit(), detector);
    std::size_t stored = 1;
    NeighbourOverlaps neighbours([&](std::size_t i) { return prepared.at(i).Expand(); },
                                 [&] { return stored; }, detector.verification);
    EXPECT_TRUE(std::isnan(neighbours.Of(0)));
    EXPECT_EQ(neighbours.registered(), 0U);
    stored = 2;
    EXPECT_GT(neighbours.Of(0), 0.8);
    // A skipped scan (empty) has none.
    NeighbourOverlaps with_a_gap(
        [&](std::size_t i) {
            return i == 1 ? registration::PreparedScan{} : prepared.at(i).Expand();
        },
        [&] { return prepared.size(); }, detector.verification);
    EXPECT_TRUE(std::isnan(with_a_gap.Of(1)));
    EXPECT_TRUE(std::isnan(with_a_gap.Of(2)));
}

TEST(CheckAgainstNeighbours, RejectsLoopsFarBelowTheLowerReference) {
    const std::vector<double> reference = {0.8, 0.9, kNan, 0.6};
    const LoopCheck check =
        CheckAgainstNeighbours([&](std::size_t i) { return reference.at(i); }, 0.5);
    ASSERT_TRUE(check);
    EXPECT_FALSE(check.may_close || check.view_distance_m || check.allowed_poses);
    // Query 3 (reference 0.6): the lower reference of 3 and 0 is 0.6, so the bar is 0.3.
    LoopQuery query = AcceptedQuery(3, {0, 1, 2}, {0.29, 0.31, 0.1});
    check(query);
    EXPECT_EQ(query.verifications[0].reason, RejectReason::kUnlikeNeighbours);
    EXPECT_FALSE(query.verifications[0].accepted);
    EXPECT_TRUE(query.verifications[1].accepted) << "0.31 >= 0.5 * min(0.6, 0.9)";
    EXPECT_FALSE(query.verifications[2].accepted) << "scan 2 has none, query 3 judges: 0.1 < 0.3";
    EXPECT_EQ(
        std::count_if(query.verifications.begin(), query.verifications.end(),
                      [](const auto& v) { return v.reason == RejectReason::kUnlikeNeighbours; }),
        2);
    ASSERT_TRUE(query.loop().has_value());
    EXPECT_EQ(*query.loop(), 1U);
    EXPECT_TRUE(query.accepted);
    // Neither scan with a reference: nothing judges.
    LoopQuery unknown = AcceptedQuery(2, {2}, {0.01});
    check(unknown);
    EXPECT_TRUE(unknown.verifications[0].accepted);
    // Every loop rejected: the query has none.
    LoopQuery lost = AcceptedQuery(1, {0}, {0.39});
    check(lost);
    EXPECT_FALSE(lost.accepted);
    EXPECT_FALSE(lost.loop().has_value());
}

// A reference costs a registration: it is asked for only where it may decide.
TEST(CheckAgainstNeighbours, AsksForAReferenceOnlyWhereItMayDecide) {
    std::vector<std::size_t> asked;
    const std::vector<double> reference = {0.9, 0.2, 0.9, 0.9};
    const LoopCheck check = CheckAgainstNeighbours(
        [&](std::size_t i) {
            asked.push_back(i);
            return reference.at(i);
        },
        0.5);
    LoopQuery sure = AcceptedQuery(3, {0}, {0.5});
    check(sure);
    EXPECT_TRUE(sure.accepted);
    EXPECT_TRUE(asked.empty()) << "0.5 >= 0.5 * any reference";
    // Query 3's reference (0.9) alone rejects 0.44; the match's decides: scan 1's 0.2 keeps it.
    LoopQuery kept = AcceptedQuery(3, {1}, {0.44});
    check(kept);
    EXPECT_TRUE(kept.accepted);
    EXPECT_EQ(asked, (std::vector<std::size_t>{3, 1}));
    // Query 2's own reference keeps 0.46: scan 0's is not needed.
    asked.clear();
    LoopQuery passes = AcceptedQuery(2, {0}, {0.46});
    check(passes);
    EXPECT_TRUE(passes.accepted);
    EXPECT_EQ(asked, (std::vector<std::size_t>{2}));
}

TEST(CheckAgainstNeighbours, RatioZeroIsNoCheck) {
    EXPECT_FALSE(CheckAgainstNeighbours([](std::size_t) { return 1.0; }, 0.0));
    const auto reference_of = [](std::size_t) { return 1.0; };
    const auto step_of = [](std::size_t) { return std::optional<core::Transform>(); };
    registration::VerificationConfig config;
    config.acceptance.min_neighbour_overlap_ratio = 0.0;
    config.acceptance.motion_max_turn_deg = 0.0;
    EXPECT_FALSE(JudgeOf({}, reference_of, step_of, config));
    config.acceptance.min_neighbour_overlap_ratio = 0.5;
    EXPECT_TRUE(JudgeOf({}, reference_of, step_of, config));
    config.acceptance.min_neighbour_overlap_ratio = 0.0;
    config.acceptance.motion_max_turn_deg = 30.0;
    EXPECT_TRUE(JudgeOf({}, reference_of, step_of, config)) << "the motion rule alone";
    // Where the odometry judges, it alone does.
    LoopCheck odometry;
    odometry.reject = [](LoopQuery& q) { q.accepted = false; };
    config.acceptance.min_neighbour_overlap_ratio = 0.5;
    const LoopCheck judge = JudgeOf(odometry, reference_of, step_of, config);
    LoopQuery query = AcceptedQuery(1, {0}, {0.0});
    judge(query);
    EXPECT_TRUE(query.verifications[0].accepted) << "the odometry's check ran, not the neighbours'";
}

// Without odometry, the yaws the layouts allow (LayoutOrderOf) still bound the coarse search.
TEST(JudgeOf, KeepsTheGivenYawWindow) {
    const auto reference_of = [](std::size_t) { return 1.0; };
    registration::VerificationConfig config;
    LoopCheck layouts;
    layouts.yaw_window = [](std::size_t query, std::size_t match) {
        return registration::YawWindow{0.1 * static_cast<double>(query + match), 0.2, true};
    };
    for (const double ratio : {0.0, 0.5}) {
        config.acceptance.min_neighbour_overlap_ratio = ratio;
        const LoopCheck judge = JudgeOf(layouts, reference_of, {}, config);
        const registration::YawWindow window = judge.YawWindow(3, 1);
        EXPECT_DOUBLE_EQ(window.centre_rad, 0.4) << ratio;
        EXPECT_DOUBLE_EQ(window.half_width_rad, 0.2) << ratio;
        EXPECT_TRUE(window.half_turn_too) << ratio;
    }
    EXPECT_TRUE(JudgeOf({}, reference_of, {}, config).YawWindow(3, 1).Whole());
}

// The revisit of place 1 (scan 4 -> 0 or 1) overlaps about as much as scans 0 and 1 do: kept at
// the default ratio, rejected where a loop must overlap more than its neighbours, online and
// offline alike.
// A localisation query labelled with its index in another, longer sequence is judged as the
// scan after the map's: its neighbour is the map's last scan (it once read the map's scan of
// that index, or past the map's end: detect --map on a sequence longer than the map crashed).
TEST(NeighbourOverlaps, ALocalisationQueryTakesTheMapsLastScanAsItsNeighbour) {
    const std::vector<core::PointCloud> scans = TwoPlacesAndARevisit();
    const DetectorConfig detector = Verifying(1.5);  // every accepted loop asks for references
    core::DescriptorConfig config;
    config.method = core::Method::kRange;
    LoopDetector online(config, detector);
    for (std::size_t i = 0; i + 1 < scans.size(); ++i)
        online.Process(scans[i], static_cast<double>(i));
    const registration::PreparedScan revisit =
        registration::PrepareScan(scans.back(), detector.verification.reduction);
    const core::Descriptor descriptor = ComputeDescriptor(scans.back(), config);
    const LoopQuery as_next = online.Query(descriptor, revisit);
    for (const std::size_t label : {std::size_t{1}, std::size_t{4}, std::size_t{40}}) {
        LoopQuery labelled;
        ASSERT_NO_THROW(labelled =
                            online.Query(*online.database().Prepare(descriptor), label, revisit));
        EXPECT_EQ(labelled.query, label);
        ASSERT_EQ(labelled.verifications.size(), as_next.verifications.size()) << label;
        for (std::size_t c = 0; c < labelled.verifications.size(); ++c)
            EXPECT_EQ(labelled.verifications[c].reason, as_next.verifications[c].reason) << label;
    }
}

TEST(NeighbourOverlaps, DetectorsJudgeLoopsAgainstTheNeighbours) {
    const std::vector<core::PointCloud> scans = TwoPlacesAndARevisit();
    for (const double ratio : {0.5, 1.5}) {
        const test::Detections detections = test::DetectBothWays(scans, Verifying(ratio));
        const std::vector<LoopQuery>& online_results = detections.online;
        const std::vector<LoopQuery>& offline = detections.offline;
        for (const LoopQuery* query : {&online_results[4], &offline[4]}) {
            // Both candidates are place 1: the first registered is the loop, or both fail.
            ASSERT_EQ(query->candidates.size(), 2U) << ratio;
            const registration::Verification& first = query->verifications.front();
            if (ratio < 1.0) {
                EXPECT_TRUE(first.accepted) << ratio;
                EXPECT_TRUE(query->accepted) << ratio;
            } else {
                for (const auto& verdict : query->verifications)
                    EXPECT_EQ(verdict.reason, RejectReason::kUnlikeNeighbours) << ratio;
                EXPECT_FALSE(query->accepted) << ratio;
            }
        }
        EXPECT_EQ(online_results[4].accepted, offline[4].accepted) << ratio;
    }
}

}  // namespace
}  // namespace lidarloop::pipeline

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/pipeline/neighbour_overlaps.hpp"
#include "pipeline/detect_both_ways.hpp"
#include "registration/registration_test_utils.hpp"

namespace lidarloop::pipeline {
namespace {

using registration::RejectReason;

// Steps of a chain: scan i in the frame of scan i - 1, i >= 1 (index 0 unused).
struct Chain {
    std::vector<std::optional<core::Transform>> steps{std::nullopt};
    mutable std::vector<std::size_t> asked;

    void Add(double forward_m, double yaw_deg, double sideways_m = 0.0) {
        steps.push_back(test::PlanarTransform(forward_m, sideways_m, yaw_deg));
    }
    StepOf Of() const {
        return [this](std::size_t i) {
            asked.push_back(i);
            return i < steps.size() ? steps[i] : std::nullopt;
        };
    }
};

Chain Straight(int steps, double step_m) {
    Chain chain;
    for (int i = 0; i < steps; ++i) chain.Add(step_m, 0.0);
    return chain;
}

TEST(MotionRulesOutLoop, AChainThatGoesStraightOnCannotComeBack) {
    const registration::AcceptanceConfig config;  // every chain; 10 m + 3 m + 0.1 x path
    const Chain chain = Straight(20, 2.0);        // 40 m straight on: 40 > 10 + 3 + 4
    EXPECT_TRUE(MotionRulesOutLoop(20, 0, chain.Of(), config));
    // 13.5 m on is still within 10 + 3 + 0.1 x 13.5 = 14.35 m: the chain may be off by that much.
    EXPECT_FALSE(MotionRulesOutLoop(9, 0, Straight(9, 1.5).Of(), config));
    EXPECT_TRUE(MotionRulesOutLoop(10, 0, Straight(10, 1.5).Of(), config)) << "15 m > 14.5 m";
    // A wobbling heading.
    Chain wobbling;
    for (int i = 0; i < 20; ++i) wobbling.Add(2.0, i % 2 == 0 ? 20.0 : -20.0);
    EXPECT_TRUE(MotionRulesOutLoop(20, 0, wobbling.Of(), config));
}

// At the default every chain is judged, however it turns: a U-turn and a block driven round
// come back, a corner and 40 m on does not.
TEST(MotionRulesOutLoop, AChainThatTurnsIsJudgedByWhereItEnds) {
    const registration::AcceptanceConfig config;
    Chain u_turn;  // 20 m out, a half turn in five steps, 20 m back: 3.1 m from the start
    for (int i = 0; i < 10; ++i) u_turn.Add(2.0, 0.0);
    for (int i = 0; i < 5; ++i) u_turn.Add(1.0, i == 0 ? 0.0 : 45.0);
    for (int i = 0; i < 10; ++i) u_turn.Add(2.0, 0.0);
    EXPECT_FALSE(MotionRulesOutLoop(25, 0, u_turn.Of(), config));
    EXPECT_EQ(u_turn.asked.back(), 25U) << "walked to the query";
    Chain
        block;  // four sides of about 40 m, turning 90 degrees at each corner: 2.8 m from the start
    for (int side = 0; side < 4; ++side) {
        for (int i = 0; i < 20; ++i) block.Add(2.0, i == 0 && side > 0 ? 90.0 : 0.0);
    }
    EXPECT_FALSE(MotionRulesOutLoop(80, 0, block.Of(), config));
    EXPECT_TRUE(MotionRulesOutLoop(40, 0, block.Of(), config))
        << "one side on from the corner: 56.6 m > 10 + 3 + 0.1 x 80 m";
    Chain corner = Straight(10, 2.0);  // 22 m on, a right angle, 20 m: 29.7 m > 10 + 3 + 8.4
    corner.Add(2.0, 90.0);
    for (int i = 0; i < 10; ++i) corner.Add(2.0, 0.0);
    EXPECT_TRUE(MotionRulesOutLoop(21, 0, corner.Of(), config));
}

// A smaller bound judges only chains that stay within it of the match's heading.
TEST(MotionRulesOutLoop, AChainThatTurnsPastTheBoundIsNotJudgedAndWalkedNoFurther) {
    registration::AcceptanceConfig config;
    config.motion_max_turn_deg = 30.0;
    Chain u_turn;  // 20 m out, a half turn in five steps, 20 m back
    for (int i = 0; i < 10; ++i) u_turn.Add(2.0, 0.0);
    for (int i = 0; i < 5; ++i) u_turn.Add(1.0, i == 0 ? 25.0 : 38.75);
    for (int i = 0; i < 10; ++i) u_turn.Add(2.0, 0.0);
    EXPECT_FALSE(MotionRulesOutLoop(25, 0, u_turn.Of(), config));
    EXPECT_EQ(u_turn.asked.back(), 12U) << "left at the first step past 30 degrees (63.75 at 12)";
    // A turn of 90 degrees and 40 m on: far, but the chain's heading left the window.
    Chain corner = Straight(10, 2.0);
    corner.Add(2.0, 90.0);
    for (int i = 0; i < 10; ++i) corner.Add(2.0, 0.0);
    EXPECT_FALSE(MotionRulesOutLoop(21, 0, corner.Of(), config));
    registration::AcceptanceConfig wide = config;
    wide.motion_max_turn_deg = 120.0;
    EXPECT_TRUE(MotionRulesOutLoop(21, 0, corner.Of(), wide)) << "within 120 degrees: judged";
}

TEST(MotionRulesOutLoop, ASensorThatBacksUpWithoutTurningMayComeBack) {
    const registration::AcceptanceConfig config;
    Chain back_and_forth = Straight(10, 2.0);
    for (int i = 0; i < 10; ++i) back_and_forth.Add(-2.0, 0.0);
    EXPECT_FALSE(MotionRulesOutLoop(20, 0, back_and_forth.Of(), config))
        << "straight, but the chain ends where it started";
}

TEST(MotionRulesOutLoop, TheStepsComposeInOrder) {
    // 10 m on while turning by 25 degrees, then 10 m on along the new heading: 19.5 m from the
    // start. Composed the other way round (the later step first) it would be 20 m.
    Chain chain;
    chain.Add(10.0, 25.0);
    chain.Add(10.0, 0.0);
    registration::AcceptanceConfig config;
    config.motion_drift_ratio = 0.0;
    config.motion_drift_m = 9.75;  // 10 + 9.75 m: between the two
    EXPECT_FALSE(MotionRulesOutLoop(2, 0, chain.Of(), config));
    config.motion_drift_m = 9.4;
    EXPECT_TRUE(MotionRulesOutLoop(2, 0, chain.Of(), config));
}

TEST(MotionRulesOutLoop, UnknownStepsAreNotJudgedAndZeroDegreesIsOff) {
    const registration::AcceptanceConfig config;
    Chain gap = Straight(20, 2.0);
    gap.steps[7] = std::nullopt;  // a pair ICP did not register
    EXPECT_FALSE(MotionRulesOutLoop(20, 0, gap.Of(), config));
    const Chain chain = Straight(20, 2.0);
    registration::AcceptanceConfig off = config;
    off.motion_max_turn_deg = 0.0;
    EXPECT_FALSE(MotionRulesOutLoop(20, 0, chain.Of(), off));
    EXPECT_FALSE(CheckAgainstMotion(chain.Of(), off));
}

TEST(CheckAgainstMotion, RejectsTheLoopsTheMotionRulesOutAndChoosesAgain) {
    const registration::AcceptanceConfig config;
    Chain chain = Straight(10, 0.5);                   // scans 0..10 within 5 m
    for (int i = 0; i < 20; ++i) chain.Add(2.0, 0.0);  // then 40 m straight on to scan 30
    LoopQuery query;
    query.query = 30;
    for (const std::size_t match : {2U, 12U, 29U}) {  // 44, 36 and 2 m back along the chain
        query.candidates.push_back({match, 0.0});
        registration::Verification verdict;
        verdict.accepted = true;
        verdict.overlap.query_fraction = verdict.overlap.match_fraction =
            match == 2 ? 0.9 : 0.5;  // the far one overlaps best: it would be the loop
        query.verifications.push_back(verdict);
    }
    query.accepted = true;
    ASSERT_EQ(query.loop(), 0U);
    CheckAgainstMotion(chain.Of(), config)(query);
    EXPECT_EQ(query.verifications[0].reason, RejectReason::kUnlikeMotion);
    EXPECT_EQ(query.verifications[1].reason, RejectReason::kUnlikeMotion);
    EXPECT_TRUE(query.verifications[2].accepted) << "2 m back: a loop may be there";
    EXPECT_EQ(query.loop(), 2U);
    EXPECT_TRUE(query.accepted);
    EXPECT_EQ(registration::ToString(RejectReason::kUnlikeMotion), "unlike_motion");
}

// A street that repeats every 60 m, scanned every 5 m for 60 m: the last scan sees what the
// first saw and registers to it at 0 m. Seen from within, it is the first place again; but the
// scans between, each registered to the one before, went 60 m straight on. Offline the motion
// rule rejects that loop; the online detector, which does not chain its scans, keeps it.
std::vector<core::PointCloud> RepeatingStreetDrivenStraight() {
    const core::PointCloud place = test::SyntheticPlace(1);  // a street from x = -30 to 30 m
    std::vector<core::PointCloud> scans;
    for (double x = 0.0; x <= 60.0; x += 5.0) {
        core::PointCloud scan;
        for (const double copy_m : {0.0, 60.0, 120.0}) {
            for (const auto& p : place) {
                const float along = p.x() + static_cast<float>(copy_m - x);  // sensor frame
                if (std::abs(along) <= 28.0F) scan.emplace_back(along, p.y(), p.z());
            }
        }
        scans.push_back(std::move(scan));
    }
    return scans;
}

TEST(MotionRule, OfflineDetectionRejectsALookAlikeReachedStraightOn) {
    const std::vector<core::PointCloud> scans = RepeatingStreetDrivenStraight();
    for (const double max_turn_deg : {0.0, registration::AcceptanceConfig{}.motion_max_turn_deg}) {
        DetectorConfig detector;
        detector.min_gap = {5.0, core::MinGap::Unit::kScans};
        detector.min_path_m = 0.0;
        detector.top_k = 3;
        detector.verification.acceptance.motion_max_turn_deg = max_turn_deg;
        const test::Detections detections = test::DetectBothWays(scans, detector);
        // Online the rule is off (docs/verification.md): the look-alike stays either way.
        const LoopQuery& online_last = detections.online.back();
        ASSERT_TRUE(online_last.loop().has_value()) << max_turn_deg;
        EXPECT_EQ(online_last.candidates[*online_last.loop()].index, 0U);
        const LoopQuery& last = detections.offline.back();
        if (max_turn_deg == 0.0) {
            ASSERT_TRUE(last.loop().has_value()) << "without the rule: the look-alike";
            EXPECT_EQ(last.candidates[*last.loop()].index, 0U);
            continue;
        }
        EXPECT_FALSE(last.accepted);
        EXPECT_TRUE(
            std::any_of(last.verifications.begin(), last.verifications.end(),
                        [](const auto& v) { return v.reason == RejectReason::kUnlikeMotion; }));
    }
}

}  // namespace
}  // namespace lidarloop::pipeline

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "eval/eval_test_utils.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/ground_truth.hpp"
#include "test_utils.hpp"

namespace lidarloop::eval {
namespace {

using core::MinGap;
using test::MakePose;
using test::RandomTrajectory;

using test::kDeg;

// The O(n^2) reference: every pair, the rules written out again.
struct BruteTruth {
    std::vector<LoopPair> loops;
    std::vector<std::size_t> nearest;
    std::vector<double> nearest_distance_m;
    std::size_t comparable_pairs = 0;
};

// The gap and the path rule, written out again.
bool BruteComparable(const std::vector<core::StampedPose>& poses, const GroundTruthConfig& c,
                     std::size_t i, std::size_t j) {
    if (i == j) return false;
    const double path_m = test::BrutePathM(poses, i, j);
    if (c.min_path_m > 0.0 && !(path_m > c.min_path_m)) return false;
    switch (c.min_gap.unit) {
        case MinGap::Unit::kScans:
            return static_cast<double>(std::max(i, j) - std::min(i, j)) > c.min_gap.value;
        case MinGap::Unit::kSeconds:
            return std::abs(poses[i].time_s - poses[j].time_s) > c.min_gap.value;
        case MinGap::Unit::kMetres:
            return path_m > c.min_gap.value;
    }
    return false;
}

BruteTruth BruteForce(const std::vector<core::StampedPose>& poses, const GroundTruthConfig& c) {
    const std::size_t n = poses.size();
    std::vector<Eigen::Vector3d> position(n);
    for (std::size_t i = 0; i < n; ++i) position[i] = poses[i].T_world_sensor.translation();
    const auto rules = [&](std::size_t i, std::size_t j) {
        if (!BruteComparable(poses, c, i, j)) return false;
        return c.max_heading_deg == 0.0 ||
               HeadingDifferenceDeg(poses[i].T_world_sensor, poses[j].T_world_sensor) <
                   c.max_heading_deg;
    };
    BruteTruth truth;
    truth.nearest.assign(n, kNoScan);
    truth.nearest_distance_m.assign(n, std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < n; ++i) {
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t j = 0; j < n; ++j) {
            if (i < j && BruteComparable(poses, c, i, j)) ++truth.comparable_pairs;
            const double squared = (position[i] - position[j]).squaredNorm();
            const bool near = i < j && squared < c.distance_m * c.distance_m;
            // The rules are the expensive part; a pair that can change nothing skips them.
            if (!(near || squared < best) || !rules(i, j)) continue;
            if (near) truth.loops.push_back({i, j, (position[i] - position[j]).norm()});
            if (squared < best) {
                best = squared;
                truth.nearest[i] = j;
                truth.nearest_distance_m[i] = std::sqrt(squared);
            }
        }
    }
    return truth;
}

// IsLoop, on every ordered pair (i == j included), answers exactly as the list of loops, and
// each scan's first partner is its smallest one in the list.
void ExpectIsLoopAsListed(const GroundTruth& truth, const std::vector<LoopPair>& loops) {
    const std::size_t n = truth.size();
    std::vector<bool> listed(n * n, false);
    std::vector<std::size_t> first(n, kNoScan);
    for (const LoopPair& loop : loops) {
        listed[loop.i * n + loop.j] = listed[loop.j * n + loop.i] = true;
        first[loop.i] = std::min(first[loop.i], loop.j);
        first[loop.j] = std::min(first[loop.j], loop.i);
    }
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = 0; j < n; ++j) wrong += truth.IsLoop(i, j) != listed[i * n + j];
    }
    EXPECT_EQ(wrong, 0u) << "pairs where IsLoop disagrees with the list";
    EXPECT_EQ(truth.first_partner, first);
}

void ExpectSameAsBruteForce(const std::vector<core::StampedPose>& poses,
                            const GroundTruthConfig& config) {
    const GroundTruth truth = BuildGroundTruth(poses, config);
    const BruteTruth expected = BruteForce(poses, config);
    const std::vector<LoopPair> loops = truth.Loops();
    ASSERT_EQ(loops.size(), expected.loops.size()) << config.Describe();
    EXPECT_EQ(truth.loop_count, expected.loops.size());
    for (std::size_t k = 0; k < loops.size(); ++k) {
        EXPECT_EQ(loops[k].i, expected.loops[k].i);
        EXPECT_EQ(loops[k].j, expected.loops[k].j);
        EXPECT_EQ(loops[k].distance_m, expected.loops[k].distance_m);
    }
    EXPECT_EQ(truth.nearest, expected.nearest) << config.Describe();
    EXPECT_EQ(truth.nearest_distance_m, expected.nearest_distance_m);
    EXPECT_EQ(truth.ComparablePairCount(), expected.comparable_pairs);
    // The adjacency, Overlapping and the nearest distance tell the same story.
    std::size_t overlapping = 0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
        EXPECT_EQ(truth.Overlapping(i), truth.nearest_distance_m[i] < config.distance_m);
        overlapping += truth.Overlapping(i) ? 1 : 0;
    }
    EXPECT_EQ(truth.OverlappingCount(), overlapping);
    ExpectIsLoopAsListed(truth, expected.loops);
}

TEST(GroundTruth, KdTreeEqualsBruteForceOnRandomTrajectories) {
    std::vector<GroundTruthConfig> configs(6);
    configs[1].min_gap = {30.0, MinGap::Unit::kScans};
    configs[2].min_gap = {12.5, MinGap::Unit::kSeconds};
    configs[3].distance_m = 5.0;
    configs[3].max_heading_deg = 20.0;
    configs[3].min_gap = {10.0, MinGap::Unit::kScans};
    configs[4].distance_m = 3.0;
    configs[4].max_heading_deg = 45.0;
    configs[4].min_gap = {4.0, MinGap::Unit::kSeconds};
    configs[5].distance_m = 25.0;
    configs[5].min_gap = {2.5, MinGap::Unit::kScans};  // fractional S: |i - j| >= 3
    // Under the sanitizers one trajectory (three took 36 s there), else three.
    const std::vector<unsigned> seeds =
        test::kSanitizedBuild ? std::vector<unsigned>{1} : std::vector<unsigned>{1, 2, 3};
    for (const unsigned seed : seeds) {
        const auto poses = RandomTrajectory(seed, 500);
        for (const auto& config : configs) {
            SCOPED_TRACE("seed " + std::to_string(seed) + ": " + config.Describe());
            ExpectSameAsBruteForce(poses, config);
        }
    }
}

// Revisits as SLAM users count them: a metres gap, and min_path_m beside a gap in scans or
// seconds, against the brute force that walks the path between every pair anew.
TEST(GroundTruth, PathRulesEqualBruteForce) {
    std::vector<GroundTruthConfig> configs(4);
    configs[0].min_gap = {60.0, MinGap::Unit::kMetres};
    configs[1].min_gap = {10.0, MinGap::Unit::kScans};
    configs[1].min_path_m = 50.0;
    configs[2].min_gap = {2.0, MinGap::Unit::kSeconds};
    configs[2].min_path_m = 80.0;
    configs[3].distance_m = 5.0;
    configs[3].max_heading_deg = 30.0;
    configs[3].min_gap = {20.0, MinGap::Unit::kMetres};
    configs[3].min_path_m = 40.0;
    for (const unsigned seed : {4u, 5u}) {
        const auto poses = RandomTrajectory(seed, 400);
        for (const auto& config : configs) {
            SCOPED_TRACE("seed " + std::to_string(seed) + ": " + config.Describe());
            ExpectSameAsBruteForce(poses, config);
        }
    }
    // Times out of order: the pair count cannot bisect on them.
    auto shuffled = RandomTrajectory(6, 200);
    std::reverse(shuffled.begin(), shuffled.end());
    for (std::size_t i = 0; i < shuffled.size(); i += 2) shuffled[i].time_s = -shuffled[i].time_s;
    ExpectSameAsBruteForce(shuffled, configs[2]);
}

TEST(GroundTruth, HandMadeSequence) {
    // Scans 0..5 on a line 4 m apart, then scan 6 back at scan 1 facing the other way.
    std::vector<core::StampedPose> poses;
    for (int i = 0; i < 6; ++i) poses.push_back(MakePose(i, 4.0 * i, 0.0));
    poses.push_back(MakePose(6, 4.0, 1.0, std::numbers::pi));
    GroundTruthConfig config;
    config.distance_m = 5.0;
    config.min_gap = {2.0, MinGap::Unit::kScans};
    const GroundTruth truth = BuildGroundTruth(poses, config);
    const std::vector<LoopPair> loops = truth.Loops();
    ASSERT_EQ(loops.size(), 3u);  // (0,6) 4.12 m, (1,6) 1 m, (2,6) 4.12 m
    EXPECT_EQ(loops[0].i, 0u);
    EXPECT_EQ(loops[1].i, 1u);
    EXPECT_DOUBLE_EQ(loops[1].distance_m, 1.0);
    EXPECT_EQ(loops[2].i, 2u);
    EXPECT_EQ(truth.first_partner[6], 0u);
    EXPECT_EQ(truth.first_partner[0], 6u);
    EXPECT_EQ(truth.nearest[6], 1u);
    EXPECT_EQ(truth.nearest[3], 6u);  // 3 is 2 scans from 1 and 5: only 0 and 6 are outside
    EXPECT_DOUBLE_EQ(truth.nearest_distance_m[3], std::sqrt(64.0 + 1.0));
    EXPECT_FALSE(truth.Overlapping(3));
    EXPECT_TRUE(truth.Overlapping(6));
    EXPECT_EQ(truth.OverlappingCount(), 4u);
    // The heading rule removes them all: scan 6 faces the other way.
    config.max_heading_deg = 20.0;
    const GroundTruth directed = BuildGroundTruth(poses, config);
    EXPECT_EQ(directed.loop_count, 0u);
    EXPECT_FALSE(directed.IsLoop(1, 6));
    EXPECT_EQ(directed.nearest[6], kNoScan);
    EXPECT_EQ(directed.nearest_distance_m[6], std::numeric_limits<double>::infinity());
    EXPECT_EQ(directed.nearest[0], 3u);
}

// Scans on a grid of whole metres (exact in double): many pairs lie exactly at the distance
// limit, exactly the gap apart in scans, or with times exactly the gap apart in seconds; such a
// pair is never positive, since every rule is a strict inequality.
TEST(GroundTruth, BoundariesAreExclusiveAndIsLoopAgreesWithBruteForce) {
    std::vector<core::StampedPose> poses;
    for (int k = 0; k < 60; ++k) {
        const double yaw = (k % 4) * 15.0 * kDeg;  // headings 0, 15, 30, 45 degrees
        poses.push_back(MakePose(0.5 * (k / 2), (k * 7) % 11, (k * 3) % 5, yaw));
    }
    std::vector<GroundTruthConfig> configs(5);
    configs[0].distance_m = 5.0;  // 3-4-5 triangles: exactly 5 m apart
    configs[1].distance_m = 4.0;
    configs[1].min_gap = {3.0, MinGap::Unit::kScans};  // |i - j| == 3 is not evaluated
    configs[2].distance_m = 5.0;
    configs[2].min_gap = {1.0, MinGap::Unit::kSeconds};  // times 1.0 s apart are not
    configs[3].distance_m = 6.0;
    configs[3].max_heading_deg = 30.0;  // 0 vs 30 degrees: not positive
    configs[4].distance_m = 2.0;
    configs[4].max_heading_deg = 16.0;
    configs[4].min_gap = {2.0, MinGap::Unit::kScans};
    for (const GroundTruthConfig& config : configs) {
        SCOPED_TRACE(config.Describe());
        ExpectSameAsBruteForce(poses, config);
        // The grid does put pairs on each boundary.
        const GroundTruth truth = BuildGroundTruth(poses, config);
        std::size_t at_distance = 0;
        for (std::size_t i = 0; i < poses.size(); ++i) {
            for (std::size_t j = i + 1; j < poses.size(); ++j) {
                const double d = (truth.positions_m[i] - truth.positions_m[j]).norm();
                at_distance += d == config.distance_m && truth.Comparable(i, j);
                if (d == config.distance_m) {
                    EXPECT_FALSE(truth.IsLoop(i, j));
                }
            }
        }
        EXPECT_GT(at_distance, 0u);
    }
}

TEST(GroundTruth, CopiesShareTheTreeAndAnswerTheSame) {
    const GroundTruth truth = BuildGroundTruth(RandomTrajectory(5, 200), GroundTruthConfig{});
    const GroundTruth copy = truth;
    EXPECT_EQ(copy.tree, truth.tree);
    EXPECT_EQ(copy.Loops().size(), truth.loop_count);
    EXPECT_GT(truth.loop_count, 0u);
}

TEST(GroundTruth, HeadingDifferenceUsesTheGroundPlane) {
    const auto heading = [](double yaw_a, double yaw_b, double pitch_b = 0.0, double roll_b = 0.0) {
        return HeadingDifferenceDeg(
            MakePose(0, 0, 0, yaw_a * kDeg).T_world_sensor,
            MakePose(0, 0, 0, yaw_b * kDeg, pitch_b * kDeg, roll_b * kDeg).T_world_sensor);
    };
    EXPECT_NEAR(heading(10, 350), 20.0, 1e-9);  // across the +-180 seam
    EXPECT_NEAR(heading(0, 180), 180.0, 1e-9);
    EXPECT_NEAR(heading(-170, 170), 20.0, 1e-9);
    EXPECT_NEAR(heading(30, 30, 0, 40), 0.0, 1e-9);  // roll does not change the heading
    EXPECT_NEAR(heading(30, 30, 25, 0), 0.0, 1e-9);  // nor does pitch
    EXPECT_NEAR(heading(0, 123, 90, 0), 0.0, 1e-6);  // looking straight down: no heading
    EXPECT_NEAR(heading(75, 20), 55.0, 1e-9);
}

TEST(GroundTruth, DescribeNamesTheRule) {
    GroundTruthConfig config;
    EXPECT_NE(config.Describe().find("10 m"), std::string::npos);
    EXPECT_NE(config.Describe().find("every pair"), std::string::npos);
    config.distance_m = 5.0;
    config.max_heading_deg = 20.0;
    config.min_gap = {30.0, MinGap::Unit::kScans};
    const std::string text = config.Describe();
    EXPECT_NE(text.find("5 m"), std::string::npos) << text;
    EXPECT_NE(text.find("20 deg"), std::string::npos) << text;
    EXPECT_NE(text.find("30 scans"), std::string::npos) << text;
    config.min_gap = {12.5, MinGap::Unit::kSeconds};
    EXPECT_NE(config.Describe().find("12.5 s"), std::string::npos);
    config.min_gap = {40.0, MinGap::Unit::kMetres};
    config.min_path_m = 50.0;
    EXPECT_NE(config.Describe().find("40 m of path"), std::string::npos) << config.Describe();
    EXPECT_NE(config.Describe().find("50 m of path apart"), std::string::npos);
    const GroundTruth truth = BuildGroundTruth(RandomTrajectory(4, 50), config);
    EXPECT_NE(truth.Describe().find("50 scans"), std::string::npos);
}

TEST(GroundTruth, EmptyAndSingleScanSequences) {
    const GroundTruth empty = BuildGroundTruth({}, GroundTruthConfig{});
    EXPECT_EQ(empty.size(), 0u);
    EXPECT_EQ(empty.ComparablePairCount(), 0u);
    const GroundTruth one = BuildGroundTruth({MakePose(0, 0, 0)}, GroundTruthConfig{});
    EXPECT_EQ(one.nearest[0], kNoScan);
    EXPECT_FALSE(one.Overlapping(0));
}

void ExpectConfigError(const GroundTruthConfig& config, const std::string& field) {
    EXPECT_TRUE(test::Contains(test::ConfigErrorOf([&] { config.Validate(); }), field));
}

TEST(GroundTruth, RejectsAbsurdConfigsAndPoses) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (const double distance : {0.0, -1.0, nan, inf}) {
        GroundTruthConfig config;
        config.distance_m = distance;
        ExpectConfigError(config, "ground_truth.distance_m");
    }
    for (const double heading : {-1.0, 181.0, nan}) {
        GroundTruthConfig config;
        config.max_heading_deg = heading;
        ExpectConfigError(config, "ground_truth.max_heading_deg");
    }
    GroundTruthConfig gap;
    gap.min_gap.value = -3.0;
    ExpectConfigError(gap, "ground_truth.min_gap");
    for (const double path : {-1.0, nan, inf}) {
        GroundTruthConfig config;
        config.min_path_m = path;
        ExpectConfigError(config, "ground_truth.min_path_m");
    }
    EXPECT_THROW(BuildGroundTruth({}, gap), core::ConfigError);
    std::vector<core::StampedPose> poses{MakePose(0, 0, 0), MakePose(1, nan, 0)};
    EXPECT_THROW(BuildGroundTruth(poses, GroundTruthConfig{}), core::Error);
    poses[1] = MakePose(nan, 1, 0);
    EXPECT_THROW(BuildGroundTruth(poses, GroundTruthConfig{}), core::Error);
}

}  // namespace
}  // namespace lidarloop::eval

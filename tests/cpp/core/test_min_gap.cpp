#include <cmath>
#include <cstddef>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "test_utils.hpp"

namespace lidarloop::core {
namespace {

// A wandering trajectory with stops (repeated positions) and vertical steps; seeded.
std::vector<StampedPose> Wander(unsigned seed, std::size_t count) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> step(0.0, 0.4);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<StampedPose> poses(count);
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < count; ++i) {
        if (unit(rng) > 0.1) position += Eigen::Vector3d{step(rng), step(rng), 0.2 * step(rng)};
        poses[i].time_s = 0.1 * static_cast<double>(i);
        poses[i].T_world_sensor.translation() = position;
    }
    return poses;
}

TEST(MinGap, MetresCountThePathBetweenTheScans) {
    const std::vector<StampedPose> poses = Wander(7, 150);
    const std::vector<double> path_m = CumulativePathM(poses);
    ASSERT_EQ(path_m.size(), poses.size());
    const MinGap gap{5.0, MinGap::Unit::kMetres};
    std::size_t allowed = 0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
        for (std::size_t j = 0; j < poses.size(); ++j) {
            const double brute_m = test::BrutePathM(poses, i, j);
            EXPECT_NEAR(std::abs(path_m[i] - path_m[j]), brute_m, 1e-9);
            EXPECT_EQ(gap.Allows(i, j, path_m[i], path_m[j]), brute_m > gap.value)
                << i << ", " << j << ": " << brute_m << " m";
            allowed += brute_m > gap.value ? 1 : 0;
        }
    }
    EXPECT_GT(allowed, 0u);
    EXPECT_LT(allowed, poses.size() * (poses.size() - 1));  // the gap excludes some pairs
}

TEST(MinGap, MetresIgnoreTheIndexAndTimeAndAlongPicksThePath) {
    const MinGap metres{10.0, MinGap::Unit::kMetres};
    EXPECT_FALSE(metres.Allows(0, 1000, 3.0, 12.0));  // 1000 scans but 9 m of path
    EXPECT_TRUE(metres.Allows(0, 1, 12.5, 2.0));      // 1 scan but 10.5 m
    const std::vector<double> times_s{0.0, 1.0}, path_m{0.0, 20.0};
    EXPECT_EQ(&metres.Along(times_s, path_m), &path_m);
    const MinGap seconds{10.0, MinGap::Unit::kSeconds};
    EXPECT_EQ(&seconds.Along(times_s, path_m), &times_s);
}

TEST(MinGap, CumulativePathOfStopsAndBadPoses) {
    EXPECT_TRUE(CumulativePathM({}).empty());
    std::vector<StampedPose> poses(3);
    poses[1].T_world_sensor.translation() = Eigen::Vector3d(3.0, 4.0, 0.0);
    poses[2].T_world_sensor.translation() = Eigen::Vector3d(3.0, 4.0, 0.0);  // a stop
    EXPECT_EQ(CumulativePathM(poses), (std::vector<double>{0.0, 5.0, 5.0}));
    poses[2].T_world_sensor.translation().x() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(CumulativePathM(poses), Error);
}

TEST(MinGap, AGivenPathMustBeFiniteAndNeverShrink) {
    EXPECT_NO_THROW(CheckPathM(std::vector<double>{}, "path"));
    EXPECT_NO_THROW(CheckPathM(std::vector<double>{0.0, 2.0, 2.0, 7.5}, "path"));
    try {
        CheckPathM(std::vector<double>{0.0, 3.0, 1.0}, "given path");
        ADD_FAILURE() << "a shrinking path passed";
    } catch (const ConfigError& e) {
        EXPECT_TRUE(
            test::Contains(e.what(), "given path: scan 2's path (1.000000 m) lies before scan 1"));
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_THROW(CheckPathM(std::vector<double>{0.0, nan, 5.0}, "path"), ConfigError);
    EXPECT_THROW(CheckPathM(std::vector<double>{0.0, inf}, "path"), ConfigError);
    // Frames of a longer drive whose path shrinks: the drive's path is checked, not trusted.
    std::vector<StampedPose> frames(2);
    frames[0].path_m = 10.0;
    frames[1].path_m = 4.0;
    EXPECT_THROW(CumulativePathM(frames), Error);
    frames[1].path_m = nan;
    EXPECT_THROW(CumulativePathM(frames), Error);
}

}  // namespace
}  // namespace lidarloop::core

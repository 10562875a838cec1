#include "lidarloop/registration/submap.hpp"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

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
        scan.emplace_back(coordinate(random), coordinate(random), 0.1F * coordinate(random));
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

}  // namespace
}  // namespace lidarloop::registration

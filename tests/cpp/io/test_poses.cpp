#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "io/io_test_utils.hpp"
#include "lidarloop/io/poses.hpp"

namespace lidarloop::io {
namespace {

using test::Contains;
using test::ReadErrorOf;

core::Transform MakeTransform(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
    core::Transform T = core::Transform::Identity();
    T.linear() = R;
    T.translation() = t;
    return T;
}

double MaxDifference(const core::Transform& a, const core::Transform& b) {
    return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

std::vector<core::StampedPose> RandomPoses(std::size_t count, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> normal;
    std::vector<core::StampedPose> poses(count);
    for (std::size_t i = 0; i < count; ++i) {
        const Eigen::Quaterniond q{normal(rng), normal(rng), normal(rng), normal(rng)};
        poses[i].time_s = static_cast<double>(i);
        poses[i].T_world_sensor =
            MakeTransform(q.normalized().toRotationMatrix(),
                          100.0 * Eigen::Vector3d{normal(rng), normal(rng), normal(rng)});
    }
    return poses;
}

const std::string kIdentityLine = "1 0 0 0 0 1 0 0 0 0 1 0\n";

// The fixture's Tr: camera x = -velo y, camera y = -velo z, camera z = velo x, offset (0.1 -0.2
// 0.3) m.
core::Transform FixtureTr() {
    Eigen::Matrix3d R;
    R << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    return MakeTransform(R, {0.1, -0.2, 0.3});
}

TEST(KittiCalib, ReadsTheTrLine) {
    const core::Transform T_cam0_velo = ReadKittiCalibTr(test::DataFile("kitti/calib.txt"));
    EXPECT_LT(MaxDifference(T_cam0_velo, FixtureTr()), 1e-15) << T_cam0_velo.matrix();
}

// With the fixture's Tr (R_cv, t_cv), worked by hand as T_velo0_veloi = Tr^-1 P_i Tr:
// P_0 = I gives I.
// P_1 = camera 2 m along its z (forward): R_cv^T (0 0 2) = (2 0 0), 2 m along velodyne x.
// P_2 = Ry(+90 deg) about the camera's y (down), t = (1 0 2): rotation R_cv^T Ry R_cv = yaw -90
// deg about velodyne z; translation R_cv^T (Ry t_cv + t - t_cv) = R_cv^T (1.2, 0, 1.6) =
// (1.6, -1.2, 0).
TEST(KittiPoses, ConvertsCameraPosesToTheLidarFrameWorkedByHand) {
    const auto poses = ReadKittiPoses(test::DataFile("kitti/poses.txt"), FixtureTr(),
                                      test::DataFile("kitti/times.txt"));
    ASSERT_EQ(poses.size(), 3U);
    EXPECT_LT(MaxDifference(poses[0].T_world_sensor, core::Transform::Identity()), 1e-15);
    EXPECT_LT(MaxDifference(poses[1].T_world_sensor,
                            MakeTransform(Eigen::Matrix3d::Identity(), {2.0, 0.0, 0.0})),
              1e-15);
    Eigen::Matrix3d yaw_minus_90;
    yaw_minus_90 << 0, 1, 0, -1, 0, 0, 0, 0, 1;
    EXPECT_LT(MaxDifference(poses[2].T_world_sensor, MakeTransform(yaw_minus_90, {1.6, -1.2, 0.0})),
              1e-14)
        << poses[2].T_world_sensor.matrix();
    EXPECT_EQ(poses[0].time_s, 0.0);
    EXPECT_EQ(poses[1].time_s, 0.1036);
    EXPECT_EQ(poses[2].time_s, 0.2072);
}

TEST(KittiPoses, IdentityCalibrationTakesPosesAsGivenAndTimesAreIndices) {
    const auto poses = ReadKittiPoses(test::DataFile("kitti/poses.txt"));
    ASSERT_EQ(poses.size(), 3U);
    EXPECT_EQ(poses[2].time_s, 2.0);
    Eigen::Matrix3d Ry_90;
    Ry_90 << 0, 0, 1, 0, 1, 0, -1, 0, 0;
    EXPECT_LT(MaxDifference(poses[2].T_world_sensor, MakeTransform(Ry_90, {1.0, 0.0, 2.0})), 1e-15);
}

TEST(KittiPoses, RoundTrip) {
    test::TempDir dir;
    const auto poses = RandomPoses(50, 3);
    WriteKittiPoses(dir / "poses.txt", poses);
    const auto read = ReadKittiPoses(dir / "poses.txt");
    ASSERT_EQ(read.size(), poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
        EXPECT_EQ(read[i].time_s, poses[i].time_s);
        EXPECT_LT(MaxDifference(read[i].T_world_sensor, poses[i].T_world_sensor), 1e-12) << i;
    }
}

TEST(KittiPoses, EmptyFileGivesNoPoses) {
    test::TempDir dir;
    test::WriteFile(dir / "poses.txt", "");
    EXPECT_TRUE(ReadKittiPoses(dir / "poses.txt").empty());
}

TEST(KittiPoses, BadLinesNameFileAndLine) {
    test::TempDir dir;
    const auto error_of = [&](const std::string& text) {
        test::WriteFile(dir / "poses.txt", text);
        return ReadErrorOf([&] { ReadKittiPoses(dir / "poses.txt"); });
    };
    EXPECT_TRUE(Contains(error_of(kIdentityLine + "1 0 0 0 0 1 0 0 0 0 1\n"),
                         "poses.txt: line 2: expected 12 numbers (3x4 row-major matrix), got 11"));
    EXPECT_TRUE(Contains(error_of(kIdentityLine + kIdentityLine + "1 0 0 0 0 1 0 0 0 0 1 0 7\n"),
                         "line 3: expected 12 numbers (3x4 row-major matrix), got 13"));
    EXPECT_TRUE(
        Contains(error_of("1 0 0 0 0 1 0 0 0 0 1 zero\n"), "line 1: 'zero' is not a number"));
    EXPECT_TRUE(Contains(error_of("1 0 0 nan 0 1 0 0 0 0 1 0\n"), "'nan' is not a finite number"));
    EXPECT_TRUE(Contains(error_of("0 0 0 0 0 0 0 0 0 0 0 0\n"),
                         "line 1: the 3x3 part is not a "
                         "rotation"));
    EXPECT_TRUE(Contains(error_of(kIdentityLine + "1 0 0 0 0 1 0 0 0 0 1 0\x01\n"),
                         "line 2: holds control character 0x01"));
    EXPECT_TRUE(
        Contains(ReadErrorOf([&] { ReadKittiPoses(dir / "none.txt"); }), "none.txt: no such file"));
}

TEST(KittiPoses, TimesCountMismatchNamesBothCounts) {
    test::TempDir dir;
    test::WriteFile(dir / "poses.txt", kIdentityLine + kIdentityLine + kIdentityLine);
    test::WriteFile(dir / "times.txt", "0\n0.1\n0.2\n0.3\n");
    const std::string message = ReadErrorOf(
        [&] { ReadKittiPoses(dir / "poses.txt", core::Transform::Identity(), dir / "times.txt"); });
    EXPECT_TRUE(Contains(message, "times.txt: holds 4 times but"));
    EXPECT_TRUE(Contains(message, "poses.txt holds 3 poses"));
    test::WriteFile(dir / "times.txt", "0\n0.1 0.2\n");
    EXPECT_TRUE(Contains(ReadErrorOf([&] {
                             ReadKittiPoses(dir / "poses.txt", core::Transform::Identity(),
                                            dir / "times.txt");
                         }),
                         "times.txt: line 2: expected 1 number (time in s), got 2"));
}

// Implausible poses are errors naming the line (issue 25, item 8); a standstill is not.
TEST(KittiPoses, ImplausiblePositionsNameTheLine) {
    test::TempDir dir;
    const auto file = dir / "poses.txt";
    const auto error_of = [&](const std::string& text, double max_step_m) {
        test::WriteFile(file, text);
        return ReadErrorOf([&] { ReadPoses(file, core::Transform::Identity(), {}, max_step_m); });
    };
    const double kAny = std::numeric_limits<double>::infinity();
    EXPECT_TRUE(Contains(error_of(kIdentityLine + "1 0 0 1e30 0 1 0 0 0 0 1 0\n", kAny),
                         "poses.txt: line 2: the position is 1e+30 m from the origin"));
    EXPECT_TRUE(Contains(error_of("1 0 0 0 0 1 0 -2e8 0 0 1 0\n", kAny), "line 1: the position"));
    // UTM coordinates are fine, and so is any step without a bound (ground truth).
    EXPECT_TRUE(Contains(error_of("1 0 0 5e5 0 1 0 9.9e6 0 0 1 0\n", 100), "no ReadError"));
    EXPECT_TRUE(
        Contains(error_of(kIdentityLine + "1 0 0 5e5 0 1 0 0 0 0 1 0\n", kAny), "no ReadError"));
    EXPECT_TRUE(Contains(error_of(kIdentityLine + "1 0 0 0 0 1 0 150 0 0 1 0\n", 100),
                         "line 2: the pose is 150 m from the one before (at most 100 m"));
    EXPECT_TRUE(
        Contains(error_of(kIdentityLine + "1 0 0 0 0 1 0 99 0 0 1 0\n", 100), "no ReadError"));
    // A standstill (identical poses) is legal.
    EXPECT_TRUE(
        Contains(error_of(kIdentityLine + kIdentityLine + kIdentityLine, 100), "no ReadError"));
}

TEST(KittiPoses, TimesThatDoNotIncreaseNameTheLine) {
    test::TempDir dir;
    test::WriteFile(dir / "poses.txt", kIdentityLine + kIdentityLine + kIdentityLine);
    const auto error_of = [&](const std::string& times) {
        test::WriteFile(dir / "times.txt", times);
        return ReadErrorOf([&] {
            ReadKittiPoses(dir / "poses.txt", core::Transform::Identity(), dir / "times.txt");
        });
    };
    EXPECT_TRUE(
        Contains(error_of("0\n0.1\n0.1\n"), "times.txt: line 3: time 0.1 repeats the time before"));
    EXPECT_TRUE(Contains(error_of("0\n0.2\n0.1\n"),
                         "times.txt: line 3: time 0.1 goes back from the time before, 0.2"));
    EXPECT_TRUE(Contains(error_of("0\n0.1\n0.2\n"), "no ReadError"));
}

TEST(KittiCalib, MissingOrBadTrLineIsAReadError) {
    test::TempDir dir;
    const std::string p0 = "P0: 718.856 0 607.1928 0 0 718.856 185.2157 0 0 0 1 0\n";
    const auto error_of = [&](const std::string& text) {
        test::WriteFile(dir / "calib.txt", text);
        return ReadErrorOf([&] { ReadKittiCalibTr(dir / "calib.txt"); });
    };
    EXPECT_TRUE(Contains(error_of(p0), "calib.txt: has no 'Tr:' line"));
    EXPECT_TRUE(Contains(error_of(""), "has no 'Tr:' line"));
    EXPECT_TRUE(Contains(error_of(p0 + "Tr: 1 0 0 0 0 1 0 0 0 0 1\n"),
                         "line 2: expected 12 numbers (3x4 row-major matrix), got 11"));
    EXPECT_TRUE(
        Contains(error_of(p0 + "Tr: 1 0 0 0 0 1 0 0 0 0 1 O\n"), "line 2: 'O' is not a number"));
    EXPECT_TRUE(Contains(error_of(p0 + "Tr: 1 0 0 inf 0 1 0 0 0 0 1 0\n"),
                         "line 2: 'inf' is not a finite number"));
    const std::string identity = "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n";
    EXPECT_TRUE(Contains(error_of(identity + p0 + identity),
                         "line 3: a second 'Tr:' line (the first is line 1)"));
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadKittiCalibTr(dir / "none.txt"); }), "no such file"));
}

TEST(TumPoses, ReadsAKnownPoseAndSkipsComments) {
    test::TempDir dir;
    test::WriteFile(dir / "traj.txt",
                    "# timestamp tx ty tz qx qy qz qw\n\n"
                    "1.5 1 2 3 0 0 0.70710678118654752 0.70710678118654752\n");
    const auto poses = ReadTumPoses(dir / "traj.txt");
    ASSERT_EQ(poses.size(), 1U);
    EXPECT_EQ(poses[0].time_s, 1.5);
    Eigen::Matrix3d yaw_90;
    yaw_90 << 0, -1, 0, 1, 0, 0, 0, 0, 1;
    EXPECT_LT(MaxDifference(poses[0].T_world_sensor, MakeTransform(yaw_90, {1, 2, 3})), 1e-15);
}

TEST(TumPoses, NormalisesQuaternionsNearUnitLength) {
    test::TempDir dir;
    // Norm 1.05: the same rotation as the unit quaternion (0, 0, 0.6, 0.8).
    test::WriteFile(dir / "traj.txt", "0 0 0 0 0 0 0.63 0.84\n");
    const auto poses = ReadTumPoses(dir / "traj.txt");
    ASSERT_EQ(poses.size(), 1U);
    const Eigen::Matrix3d expected = Eigen::Quaterniond(0.8, 0, 0, 0.6).toRotationMatrix();
    EXPECT_LT((poses[0].T_world_sensor.linear() - expected).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_NEAR(poses[0].T_world_sensor.linear().determinant(), 1.0, 1e-15);
}

TEST(TumPoses, BadLinesNameFileAndLine) {
    test::TempDir dir;
    const auto error_of = [&](const std::string& text) {
        test::WriteFile(dir / "traj.txt", text);
        return ReadErrorOf([&] { ReadTumPoses(dir / "traj.txt"); });
    };
    const std::string good = "0 0 0 0 0 0 0 1\n";
    EXPECT_TRUE(Contains(error_of(good + "1 0 0 0 0 0 0.3 0.4\n"),
                         "traj.txt: line 2: quaternion (qx qy qz qw) has norm 0.5, expected 1"));
    EXPECT_TRUE(Contains(error_of("1 0 0 0 0 0 0 0\n"),
                         "line 1: quaternion (qx qy qz qw) has "
                         "norm 0,"));
    EXPECT_TRUE(Contains(error_of("1 0 0 0 0 0 1.2 0\n"), "has norm 1.2"));
    EXPECT_TRUE(Contains(error_of(good + "1 0 0 0 0 0 1\n"),
                         "line 2: expected 8 numbers (timestamp tx ty tz qx qy qz qw), got 7"));
    EXPECT_TRUE(Contains(error_of("1 0 0 zero 0 0 0 1\n"), "line 1: 'zero' is not a number"));
    EXPECT_TRUE(Contains(error_of("1 nan 0 0 0 0 0 1\n"), "'nan' is not a finite number"));
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadTumPoses(dir / "none.txt"); }), "no such file"));
}

TEST(TumPoses, ImplausibleTimesAndPositionsNameTheLine) {
    test::TempDir dir;
    const auto error_of = [&](const std::string& text, double max_step_m) {
        test::WriteFile(dir / "traj.txt", text);
        return ReadErrorOf(
            [&] { ReadPoses(dir / "traj.txt", core::Transform::Identity(), {}, max_step_m); });
    };
    const double kAny = std::numeric_limits<double>::infinity();
    const std::string first = "1.0 0 0 0 0 0 0 1\n";
    EXPECT_TRUE(Contains(error_of(first + "0.5 0 0 0 0 0 0 1\n", kAny),
                         "traj.txt: line 2: time 0.5 goes back from the time before, 1"));
    EXPECT_TRUE(Contains(error_of(first + "1.0 0 0 0 0 0 0 1\n", kAny),
                         "line 2: time 1 repeats the time before"));
    EXPECT_TRUE(Contains(error_of(first + "2 1e30 0 0 0 0 0 1\n", kAny),
                         "line 2: the position is 1e+30 m from the origin"));
    EXPECT_TRUE(Contains(error_of(first + "2 0 0 101 0 0 0 1\n", 100),
                         "line 2: the pose is 101 m from the one before"));
    EXPECT_TRUE(Contains(error_of(first + "2 0 0 0 0 0 0 1\n3 0 0 0 0 0 0 1\n", 100),
                         "no ReadError"));  // a standstill
}

TEST(TumPoses, EmptyFileGivesNoPoses) {
    test::TempDir dir;
    test::WriteFile(dir / "traj.txt", "");
    EXPECT_TRUE(ReadTumPoses(dir / "traj.txt").empty());
}

TEST(TumPoses, RoundTrip) {
    test::TempDir dir;
    auto poses = RandomPoses(50, 4);
    for (auto& pose : poses) pose.time_s = 1.7e9 + 0.1 * pose.time_s;  // Unix times
    WriteTumPoses(dir / "traj.txt", poses);
    const auto read = ReadTumPoses(dir / "traj.txt");
    ASSERT_EQ(read.size(), poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
        EXPECT_EQ(read[i].time_s, poses[i].time_s);
        EXPECT_LT(MaxDifference(read[i].T_world_sensor, poses[i].T_world_sensor), 1e-12) << i;
    }
}

}  // namespace
}  // namespace lidarloop::io

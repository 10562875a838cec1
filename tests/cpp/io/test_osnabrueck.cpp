#include <cmath>
#include <iomanip>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "io/io_test_utils.hpp"
#include "lidarloop/io/osnabrueck.hpp"

namespace lidarloop::io {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

using test::Contains;
using test::ReadErrorOf;

// 3DTK's rotation of a .pose file, written out element by element as EulerToMatrix4 in
// 3DTK/3DTK include/slam6d/globals.icc fills it (there column-major; here row by row). Kept
// independent of the reader's AngleAxis product on purpose.
Eigen::Matrix3d Rotation3dtk(double rx, double ry, double rz) {
    const double sx = std::sin(rx), cx = std::cos(rx);
    const double sy = std::sin(ry), cy = std::cos(ry);
    const double sz = std::sin(rz), cz = std::cos(rz);
    Eigen::Matrix3d R;
    R << cy * cz, -cy * sz, sy,                                     //
        sx * sy * cz + cx * sz, -sx * sy * sz + cx * cz, -sx * cy,  //
        -cx * sy * cz + sx * sz, cx * sy * sz + sx * cz, cx * cy;
    return R;
}

std::string PoseText(const Eigen::Vector3d& t_cm, const Eigen::Vector3d& angles_deg) {
    std::ostringstream text;
    text << std::setprecision(17) << t_cm.x() << ' ' << t_cm.y() << ' ' << t_cm.z() << '\n'
         << angles_deg.x() << ' ' << angles_deg.y() << ' ' << angles_deg.z() << '\n';
    return text.str();
}

// One .frames line: the 4x4 matrix column-major (OpenGL), then a colour code.
std::string FramesLine(const Eigen::Matrix3d& R, const Eigen::Vector3d& t_cm, int code) {
    Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
    M.topLeftCorner<3, 3>() = R;
    M.topRightCorner<3, 1>() = t_cm;
    std::ostringstream text;
    text << std::setprecision(17);
    for (int i = 0; i < 16; ++i) text << M.data()[i] << ' ';  // Eigen stores column-major
    text << code << '\n';
    return text.str();
}

Eigen::Matrix3d RightTurn() {  // yaw -90 degrees: forward becomes right (-y)
    Eigen::Matrix3d R;
    R << 0, 1, 0, -1, 0, 0, 0, 0, 1;
    return R;
}

TEST(Osnabrueck, CoordinatesMapAxesAndUnits) {
    const Eigen::Vector3d p = FromOsnabrueckCoordinates({100.0, 200.0, 300.0});
    EXPECT_TRUE(p.isApprox(Eigen::Vector3d(3.0, -1.0, 2.0))) << p.transpose();
    const Eigen::Vector3d back = ToOsnabrueckCoordinates(p);
    EXPECT_TRUE(back.isApprox(Eigen::Vector3d(100.0, 200.0, 300.0))) << back.transpose();
    Eigen::Matrix3d C;
    for (int i = 0; i < 3; ++i)
        C.col(i) = FromOsnabrueckCoordinates(100.0 * Eigen::Vector3d::Unit(i));
    EXPECT_NEAR(C.determinant(), -1.0, 1e-12);  // left-handed to right-handed
}

TEST(Osnabrueck, ReadsScanFixtureWithHeaderReflectanceAndNan) {
    const core::PointCloud cloud = ReadOsnabrueck3d(test::DataFile("osnabrueck/scan000.3d"));
    ASSERT_EQ(cloud.size(), 4U);
    EXPECT_EQ(cloud[0], Eigen::Vector3f(3.0f, -1.0f, 2.0f));
    EXPECT_EQ(cloud[1], Eigen::Vector3f(10.0f, 0.5f, 0.0f));
    EXPECT_TRUE(std::isnan(cloud[2].y()));
    EXPECT_EQ(cloud[2].x(), 0.0f);
    EXPECT_EQ(cloud[3], Eigen::Vector3f(0.0f, 0.0f, -1.0f));
}

TEST(Osnabrueck, ScanRoundTripIsExact) {
    test::TempDir dir;
    core::PointCloud cloud = test::RandomCloud(3000, 21, 60.0f);
    cloud.push_back({std::nanf(""), 1.0f, 2.0f});
    WriteOsnabrueck3d(dir / "scan001.3d", cloud);
    const core::PointCloud read = ReadOsnabrueck3d(dir / "scan001.3d");
    ASSERT_EQ(read.size(), cloud.size());
    for (std::size_t i = 0; i + 1 < cloud.size(); ++i) ASSERT_EQ(read[i], cloud[i]) << i;
    EXPECT_TRUE(std::isnan(read.back().x()));
    EXPECT_EQ(read.back().z(), 2.0f);
}

TEST(Osnabrueck, ScanWriterUsesCentimetresInThe3dtkFrame) {
    test::TempDir dir;
    WriteOsnabrueck3d(dir / "scan.3d", {{3.0f, -1.0f, 2.0f}});
    EXPECT_EQ(test::ReadFile(dir / "scan.3d"), "100 200 300\n");
}

TEST(Osnabrueck, EmptyScanGivesEmptyCloud) {
    test::TempDir dir;
    test::WriteFile(dir / "scan.3d", "");
    EXPECT_TRUE(ReadOsnabrueck3d(dir / "scan.3d").empty());
    test::WriteFile(dir / "header.3d", "1024 x 768\n");
    EXPECT_TRUE(ReadOsnabrueck3d(dir / "header.3d").empty());
}

// Centimetres beyond the float range in metres: rounded as IEEE does, never a plain narrowing
// (undefined behaviour there).
TEST(Osnabrueck, CoordinatesBeyondTheFloatRangeBecomeInfinite) {
    test::TempDir dir;
    test::WriteFile(dir / "scan.3d", "1e41 1 -1e300\n");
    const core::PointCloud cloud = ReadOsnabrueck3d(dir / "scan.3d");
    ASSERT_EQ(cloud.size(), 1U);
    EXPECT_EQ(cloud[0].x(), -std::numeric_limits<float>::infinity());  // x = z_3dtk / 100
    EXPECT_EQ(cloud[0].y(), -std::numeric_limits<float>::infinity());  // y = -x_3dtk / 100
    EXPECT_EQ(cloud[0].z(), 0.01f);                                    // z = y_3dtk / 100
}

TEST(Osnabrueck, BadScanLinesNameTheLine) {
    test::TempDir dir;
    test::WriteFile(dir / "short.3d", "1 2 3\n100 200\n");
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadOsnabrueck3d(dir / "short.3d"); }),
                         "short.3d: line 2: expected at least 3 numbers, got 2"));
    test::WriteFile(dir / "word.3d", "1 2 3\n1 2 three\n");
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadOsnabrueck3d(dir / "word.3d"); }),
                         "line 2: 'three' is not a number"));
    // The "W x H" header is only skipped as the first line.
    test::WriteFile(dir / "late.3d", "1 2 3\n4 x 5\n");
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadOsnabrueck3d(dir / "late.3d"); }),
                         "line 2: 'x' is not a number"));
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadOsnabrueck3d(dir / "none.3d"); }), "no such file"));
}

TEST(Osnabrueck, PcdOrRandomBytesGiveAClearError) {
    test::TempDir dir;
    std::string pcd = "# .PCD v0.7 - Point Cloud Data\nVERSION 0.7\nFIELDS x y z\nDATA binary\n";
    pcd += std::string("\x00\x00\xc0\x3f\x00\x00\x10\xc0", 8);
    test::WriteFile(dir / "scan.3d", pcd);
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadOsnabrueck3d(dir / "scan.3d"); }),
                         "line 2: 'VERSION' is not a number"));
    std::mt19937 rng(9);
    std::string noise(512, '\0');
    for (char& c : noise) c = static_cast<char>(rng() & 0xff);
    test::WriteFile(dir / "noise.3d", noise);
    const std::string message = ReadErrorOf([&] { ReadOsnabrueck3d(dir / "noise.3d"); });
    EXPECT_TRUE(Contains(message, "noise.3d: line 1: holds control character"));
    EXPECT_TRUE(Contains(message, "binary data"));
}

// ry = +90 degrees turns about 3DTK's up axis y from z (forward) towards x (right): a right
// turn, yaw -90 degrees in the right-handed frame. The position (100, 0, 200) cm is 2 m forward
// and 1 m right.
TEST(Osnabrueck, PoseFixtureIsARightTurnWorkedByHand) {
    const core::Transform T = ReadOsnabrueckPose(test::DataFile("osnabrueck/scan000.pose"));
    EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(2.0, -1.0, 0.0))) << T.matrix();
    EXPECT_TRUE(T.linear().isApprox(RightTurn(), 1e-12)) << T.matrix();
}

// rx = +90 degrees turns 3DTK's y (up) into z (forward): here up becomes forward, a pitch about
// +y by +90 degrees (x is 3DTK's -x axis, and both frames flip the sense, so it stays positive).
TEST(Osnabrueck, PoseRollAboutThe3dtkXAxisWorkedByHand) {
    test::TempDir dir;
    test::WriteFile(dir / "scan.pose", "0 0 0\n90 0 0\n");
    const core::Transform T = ReadOsnabrueckPose(dir / "scan.pose");
    EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX()));
    EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitY()));
}

// The defining property of the conversion: transforming in 3DTK then converting equals
// converting then transforming with the converted pose.
TEST(Osnabrueck, ConvertedPoseCommutesWithTheCoordinateMapForRandomPoses) {
    test::TempDir dir;
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> angle_deg(-180.0, 180.0);
    std::uniform_real_distribution<double> cm(-5000.0, 5000.0);
    for (int trial = 0; trial < 200; ++trial) {
        const Eigen::Vector3d angles{angle_deg(rng), angle_deg(rng), angle_deg(rng)};
        const Eigen::Vector3d t_cm{cm(rng), cm(rng), cm(rng)};
        test::WriteFile(dir / "scan.pose", PoseText(t_cm, angles));
        const core::Transform T = ReadOsnabrueckPose(dir / "scan.pose");
        EXPECT_NEAR(T.linear().determinant(), 1.0, 1e-12);
        EXPECT_TRUE((T.linear().transpose() * T.linear()).isIdentity(1e-12));
        const Eigen::Matrix3d R =
            Rotation3dtk(angles.x() * kDeg, angles.y() * kDeg, angles.z() * kDeg);
        const Eigen::Vector3d p_cm{cm(rng), cm(rng), cm(rng)};
        const Eigen::Vector3d expected = FromOsnabrueckCoordinates(R * p_cm + t_cm);
        const Eigen::Vector3d actual = T * FromOsnabrueckCoordinates(p_cm);
        ASSERT_LT((expected - actual).norm(), 1e-9) << "trial " << trial;
    }
}

TEST(Osnabrueck, PoseRoundTripForRandomAndGimbalLockPoses) {
    test::TempDir dir;
    std::mt19937 rng(8);
    std::normal_distribution<double> normal;
    std::vector<core::Transform> poses;
    for (int i = 0; i < 100; ++i) {
        core::Transform T = core::Transform::Identity();
        T.linear() = Eigen::Quaterniond{normal(rng), normal(rng), normal(rng), normal(rng)}
                         .normalized()
                         .toRotationMatrix();
        T.translation() = 30.0 * Eigen::Vector3d{normal(rng), normal(rng), normal(rng)};
        poses.push_back(T);
    }
    // 3DTK ry is the yaw about the up axis: +-90 degrees is its gimbal lock.
    for (double yaw : {90.0, -90.0, 180.0}) {
        for (double roll : {0.0, 30.0}) {
            core::Transform T = core::Transform::Identity();
            T.rotate(Eigen::AngleAxisd(yaw * kDeg, Eigen::Vector3d::UnitZ()));
            T.rotate(Eigen::AngleAxisd(roll * kDeg, Eigen::Vector3d::UnitX()));
            poses.push_back(T);
        }
    }
    for (const core::Transform& T : poses) {
        WriteOsnabrueckPose(dir / "scan.pose", T);
        const core::Transform read = ReadOsnabrueckPose(dir / "scan.pose");
        ASSERT_TRUE(read.matrix().isApprox(T.matrix(), 1e-6)) << T.matrix() << "\nread\n"
                                                              << read.matrix();
        ASSERT_LT((read.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-6);
    }
}

TEST(Osnabrueck, PoseErrorsNameFileAndLine) {
    test::TempDir dir;
    const auto error_of = [&](const std::string& text) {
        test::WriteFile(dir / "scan.pose", text);
        return ReadErrorOf([&] { ReadOsnabrueckPose(dir / "scan.pose"); });
    };
    EXPECT_TRUE(Contains(error_of(""), "scan.pose: holds 0 numbers"));
    EXPECT_TRUE(Contains(error_of("1 2 3\n4 5\n"), "holds 5 numbers; a .pose file holds 6"));
    EXPECT_TRUE(Contains(error_of("1 2 3\n4 5 6\n7\n"), "line 3: more than 6 numbers"));
    EXPECT_TRUE(Contains(error_of("1 2 3\n4 abc 6\n"), "line 2: 'abc' is not a number"));
    EXPECT_TRUE(Contains(error_of("1 2 3\n4 nan 6\n"), "line 2: 'nan' is not a finite number"));
    EXPECT_TRUE(Contains(error_of("# .PCD v0.7\nVERSION 0.7\n"), "line 1: '#' is not a number"));
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadOsnabrueckPose(dir / "none.pose"); }),
                         "none.pose: no such file"));
}

// A hand-written file: an identity first step, then the final pose (the right turn of the .pose
// fixture, column-major); the last line wins.
TEST(Osnabrueck, FramesFixtureGivesTheLastLine) {
    const core::Transform T = ReadOsnabrueckFrames(test::DataFile("osnabrueck/scan000.frames"));
    EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(2.0, -1.0, 0.0))) << T.matrix();
    EXPECT_TRUE(T.linear().isApprox(RightTurn(), 1e-12)) << T.matrix();
    const core::Transform from_pose = ReadOsnabrueckPose(test::DataFile("osnabrueck/scan000.pose"));
    EXPECT_TRUE(T.isApprox(from_pose, 1e-12));
}

TEST(Osnabrueck, FramesAgreeWithPoseFilesForRandomPoses) {
    test::TempDir dir;
    std::mt19937 rng(77);
    std::uniform_real_distribution<double> angle_deg(-180.0, 180.0);
    std::uniform_real_distribution<double> cm(-3000.0, 3000.0);
    for (int trial = 0; trial < 50; ++trial) {
        const Eigen::Vector3d angles{angle_deg(rng), angle_deg(rng), angle_deg(rng)};
        const Eigen::Vector3d t_cm{cm(rng), cm(rng), cm(rng)};
        const Eigen::Matrix3d R =
            Rotation3dtk(angles.x() * kDeg, angles.y() * kDeg, angles.z() * kDeg);
        test::WriteFile(dir / "scan.frames", FramesLine(Eigen::Matrix3d::Identity(), {1, 2, 3}, 0) +
                                                 FramesLine(R, t_cm, 2));
        test::WriteFile(dir / "scan.pose", PoseText(t_cm, angles));
        const core::Transform frames = ReadOsnabrueckFrames(dir / "scan.frames");
        const core::Transform pose = ReadOsnabrueckPose(dir / "scan.pose");
        ASSERT_LT((frames.matrix() - pose.matrix()).cwiseAbs().maxCoeff(), 1e-9) << trial;
    }
}

TEST(Osnabrueck, FramesErrorsNameFileAndLine) {
    test::TempDir dir;
    const std::string identity = "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 2\n";
    const auto error_of = [&](const std::string& text) {
        test::WriteFile(dir / "scan.frames", text);
        return ReadErrorOf([&] { ReadOsnabrueckFrames(dir / "scan.frames"); });
    };
    EXPECT_TRUE(Contains(error_of(""), "scan.frames: holds no frames"));
    EXPECT_TRUE(Contains(error_of(identity + "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0\n"),
                         "line 2: expected 16 matrix values and a colour code, got 15"));
    EXPECT_TRUE(
        Contains(error_of(identity + "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 2 9\n"), "got 18 values"));
    EXPECT_TRUE(
        Contains(error_of("1 0 0 0 0 1 0 0 0 0 1 0 0 0 x 1 2\n"), "line 1: 'x' is not a number"));
    EXPECT_TRUE(Contains(error_of("1 0 0 0 0 1 0 0 0 0 1 0 nan 0 0 1 2\n"),
                         "line 1: 'nan' is not a finite number"));
    EXPECT_TRUE(Contains(error_of("2 0 0 0 0 2 0 0 0 0 2 0 0 0 0 1 2\n"), "is not a rotation"));
    EXPECT_TRUE(Contains(error_of("1 0 0 0 0 1 0 0 0 0 -1 0 0 0 0 1 2\n"), "det = -1"));
    EXPECT_TRUE(Contains(error_of("1 0 0 5 0 1 0 0 0 0 1 0 0 0 0 1 2\n"), "bottom row"));
    EXPECT_TRUE(
        Contains(ReadErrorOf([&] { ReadOsnabrueckFrames(dir / "none.frames"); }), "no such file"));
}

}  // namespace
}  // namespace lidarloop::io

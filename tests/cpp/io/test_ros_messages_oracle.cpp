// The ROS 1 message decoder against ROS's own serialiser: sensor_msgs/PointCloud2 and
// nav_msgs/Odometry built with Debian's generated message headers (libsensor-msgs-dev,
// libnav-msgs-dev; ros_serialiser.hpp), decoded by lidarloop. Also checks that the type names
// and md5sums lidarloop expects in a bag are the ones ROS generates.
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/io/ros_messages.hpp"
#include "ros_serialiser.hpp"

namespace lidarloop::io {
namespace {

constexpr std::uint8_t kRosFloat64 = 8;  // sensor_msgs::PointField::FLOAT64
constexpr std::uint8_t kRosUint16 = 4;

TEST(RosMessagesOracle, TypesAndMd5sumsAreRos) {
    EXPECT_EQ(test::RosPointCloud2Type(), kPointCloud2Type);
    EXPECT_EQ(test::RosPointCloud2Md5(), kPointCloud2Md5);
    EXPECT_EQ(test::RosOdometryType(), kOdometryType);
    EXPECT_EQ(test::RosOdometryMd5(), kOdometryMd5);
}

TEST(RosMessagesOracle, PointCloud2SerialisedByRos) {
    test::RosCloud cloud;
    cloud.sec = 1234;
    cloud.nsec = 500000000;
    cloud.frame_id = "os_sensor";
    cloud.height = 2;
    cloud.width = 2;
    cloud.fields = {{"x", 0, kRosFloat64},
                    {"y", 8, kRosFloat64},
                    {"z", 16, kRosFloat64},
                    {"ring", 24, kRosUint16}};
    cloud.point_step = 32;
    cloud.row_step = 64;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double values[4][3] = {{1, 2, 3}, {nan, 0, 0}, {-4, 5.5, 6}, {7, 8, -9}};
    cloud.data.assign(128, 0);
    for (int i = 0; i < 4; ++i) std::memcpy(cloud.data.data() + 32 * i, values[i], 24);

    const std::vector<std::uint8_t> bytes = test::RosSerialise(cloud);
    const PointCloud2Message parsed = ParsePointCloud2(bytes);
    EXPECT_DOUBLE_EQ(parsed.stamp_s, 1234.5);
    EXPECT_EQ(parsed.frame_id, "os_sensor");
    ASSERT_EQ(parsed.fields.size(), 4U);
    EXPECT_EQ(parsed.fields[3].name, "ring");
    EXPECT_EQ(parsed.fields[3].datatype, kRosUint16);
    EXPECT_EQ(parsed.data.size(), 128U);
    const core::PointCloud points = DecodePointCloud2(parsed);
    ASSERT_EQ(points.size(), 3U);  // the NaN point dropped
    EXPECT_EQ(points[0], Eigen::Vector3f(1, 2, 3));
    EXPECT_EQ(points[1], Eigen::Vector3f(-4, 5.5f, 6));
    EXPECT_EQ(points[2], Eigen::Vector3f(7, 8, -9));
}

TEST(RosMessagesOracle, OdometrySerialisedByRos) {
    test::RosOdometry odometry;
    odometry.sec = 77;
    odometry.nsec = 250000000;
    odometry.position[0] = 1.5;
    odometry.position[1] = -2.0;
    odometry.position[2] = 0.25;
    odometry.orientation_xyzw[0] = std::sqrt(0.5);  // 90 degrees about x
    odometry.orientation_xyzw[3] = std::sqrt(0.5);
    const core::StampedPose pose = ParseOdometry(test::RosSerialise(odometry));
    EXPECT_DOUBLE_EQ(pose.time_s, 77.25);
    EXPECT_TRUE(pose.T_world_sensor.translation().isApprox(Eigen::Vector3d(1.5, -2.0, 0.25)));
    EXPECT_TRUE((pose.T_world_sensor.linear() * Eigen::Vector3d::UnitY())
                    .isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
}

}  // namespace
}  // namespace lidarloop::io

#pragma once

// ROS 1's own serialiser for the oracle test of io/ros_messages (test_ros_messages_oracle.cpp),
// behind plain types: ROS 1's generated message headers need C++17 (std::allocator<void>::rebind
// is gone in C++20), so ros_serialiser.cpp is compiled as C++17 on its own.

#include <cstdint>
#include <string>
#include <vector>

namespace lidarloop::test {

struct RosField {
    std::string name;
    std::uint32_t offset = 0;
    std::uint8_t datatype = 0;
};

struct RosCloud {
    std::uint32_t sec = 0, nsec = 0;
    std::string frame_id;
    std::uint32_t height = 0, width = 0, point_step = 0, row_step = 0;
    std::vector<RosField> fields;
    std::vector<std::uint8_t> data;
};

struct RosOdometry {
    std::uint32_t sec = 0, nsec = 0;
    double position[3] = {0, 0, 0};
    double orientation_xyzw[4] = {0, 0, 0, 1};
};

/// The bytes ros::serialization writes for a sensor_msgs/PointCloud2 and a nav_msgs/Odometry.
std::vector<std::uint8_t> RosSerialise(const RosCloud& cloud);
std::vector<std::uint8_t> RosSerialise(const RosOdometry& odometry);

/// ros::message_traits' DataType and MD5Sum of the two types.
std::string RosPointCloud2Type();
std::string RosPointCloud2Md5();
std::string RosOdometryType();
std::string RosOdometryMd5();

}  // namespace lidarloop::test

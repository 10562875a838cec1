#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// ROS 1 message types lidarloop reads from bags, decoded from their serialised bytes (ROS 1
/// wire format: little-endian, strings and arrays prefixed by a uint32 length). No ROS header is
/// needed to use them; the bag reader (rosbag.hpp) hands them the bytes of each message.
inline constexpr const char* kPointCloud2Type = "sensor_msgs/PointCloud2";
inline constexpr const char* kPointCloud2Md5 = "1158d486dd51d683ce2f1be655c3c181";
inline constexpr const char* kOdometryType = "nav_msgs/Odometry";
inline constexpr const char* kOdometryMd5 = "cd5e73d190d741a2f92e81eda573aca7";

/// sensor_msgs/PointField datatypes.
enum class PointFieldType : std::uint8_t {
    kInt8 = 1,
    kUint8 = 2,
    kInt16 = 3,
    kUint16 = 4,
    kInt32 = 5,
    kUint32 = 6,
    kFloat32 = 7,
    kFloat64 = 8,
};

/// One sensor_msgs/PointField: a named value at `offset` bytes into each point.
struct PointField {
    std::string name;
    std::uint32_t offset = 0;
    std::uint8_t datatype = 0;  ///< a PointFieldType, as stored (unknown values kept)
    std::uint32_t count = 1;
};

/// A sensor_msgs/PointCloud2 with its header stamp; `data` views the serialised message.
struct PointCloud2Message {
    double stamp_s = 0.0;  ///< header.stamp, seconds
    std::string frame_id;
    std::uint32_t height = 0;  ///< 1 for an unorganised cloud
    std::uint32_t width = 0;
    std::vector<PointField> fields;
    bool is_bigendian = false;
    std::uint32_t point_step = 0;  ///< bytes per point
    std::uint32_t row_step = 0;    ///< bytes per row
    std::span<const std::uint8_t> data;
};

/// Parses the serialised bytes of a sensor_msgs/PointCloud2 (`data` views `message`, which must
/// outlive the result). Throws core::FormatError when the bytes end early or a length runs past
/// them.
PointCloud2Message ParsePointCloud2(std::span<const std::uint8_t> message);

/// The header stamp (seconds) at the start of any message with a std_msgs/Header first.
/// core::FormatError when the message is shorter than the stamp.
double ParseHeaderStamp(std::span<const std::uint8_t> message);

/// The points of a cloud: fields x, y, z of type FLOAT32 or FLOAT64 at any offset within any
/// point_step, row by row (organised clouds too); points with a non-finite coordinate (no return)
/// are dropped. Throws core::FormatError naming what is wrong: a missing x, y or z field, a
/// coordinate of another type, a field beyond point_step, rows that do not fit row_step, data
/// shorter than height * row_step, and big-endian clouds (not read).
core::PointCloud DecodePointCloud2(const PointCloud2Message& cloud);

/// Parses a nav_msgs/Odometry: its header stamp and pose (T_world_sensor from pose.pose, the
/// quaternion normalised). core::FormatError when the bytes end early or the pose is not finite,
/// or the quaternion's norm is far from 1 (< 0.9 or > 1.1).
core::StampedPose ParseOdometry(std::span<const std::uint8_t> message);

}  // namespace lidarloop::io

#include "ros_serialiser.hpp"

#include <nav_msgs/Odometry.h>
#include <ros/serialization.h>
#include <sensor_msgs/PointCloud2.h>

namespace lidarloop::test {
namespace {

template <typename Message>
std::vector<std::uint8_t> Serialise(const Message& message) {
    std::vector<std::uint8_t> bytes(ros::serialization::serializationLength(message));
    ros::serialization::OStream stream(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
    ros::serialization::serialize(stream, message);
    return bytes;
}

}  // namespace

std::vector<std::uint8_t> RosSerialise(const RosCloud& cloud) {
    sensor_msgs::PointCloud2 message;
    message.header.stamp = ros::Time(cloud.sec, cloud.nsec);
    message.header.frame_id = cloud.frame_id;
    message.height = cloud.height;
    message.width = cloud.width;
    for (const RosField& field : cloud.fields) {
        sensor_msgs::PointField f;
        f.name = field.name;
        f.offset = field.offset;
        f.datatype = field.datatype;
        f.count = 1;
        message.fields.push_back(f);
    }
    message.point_step = cloud.point_step;
    message.row_step = cloud.row_step;
    message.data = cloud.data;
    message.is_dense = false;
    return Serialise(message);
}

std::vector<std::uint8_t> RosSerialise(const RosOdometry& odometry) {
    nav_msgs::Odometry message;
    message.header.stamp = ros::Time(odometry.sec, odometry.nsec);
    message.header.frame_id = "odom";
    message.child_frame_id = "base_link";
    message.pose.pose.position.x = odometry.position[0];
    message.pose.pose.position.y = odometry.position[1];
    message.pose.pose.position.z = odometry.position[2];
    message.pose.pose.orientation.x = odometry.orientation_xyzw[0];
    message.pose.pose.orientation.y = odometry.orientation_xyzw[1];
    message.pose.pose.orientation.z = odometry.orientation_xyzw[2];
    message.pose.pose.orientation.w = odometry.orientation_xyzw[3];
    message.pose.covariance[0] = 0.01;   // not read
    message.twist.twist.linear.x = 3.0;  // not read
    return Serialise(message);
}

std::string RosPointCloud2Type() {
    return ros::message_traits::DataType<sensor_msgs::PointCloud2>::value();
}
std::string RosPointCloud2Md5() {
    return ros::message_traits::MD5Sum<sensor_msgs::PointCloud2>::value();
}
std::string RosOdometryType() { return ros::message_traits::DataType<nav_msgs::Odometry>::value(); }
std::string RosOdometryMd5() { return ros::message_traits::MD5Sum<nav_msgs::Odometry>::value(); }

}  // namespace lidarloop::test

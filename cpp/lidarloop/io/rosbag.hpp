#pragma once

#include <cstddef>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// True when lidarloop was built with ROS 1 bag support (CMake LIDARLOOP_WITH_ROSBAG, Debian's
/// librosbag-storage-dev). Without it every bag function throws ReadError saying so.
bool RosbagSupported();

/// True for a file name ending in ".bag" (any case).
bool IsBagFile(const std::filesystem::path& file);

/// One topic of a bag.
struct BagTopic {
    std::string name;      ///< e.g. "/velodyne_points"
    std::string type;      ///< e.g. "sensor_msgs/PointCloud2"
    std::size_t messages;  ///< on this topic, over all its connections
};

/// The topics of a bag, by name. ReadError naming the file for a missing, truncated or corrupt
/// bag (rosbag_storage's exceptions converted).
std::vector<BagTopic> ListBagTopics(const std::filesystem::path& bag);

/// A scan addressed inside a bag: "BAG:TOPIC:INDEX" (e.g. "run.bag:/points:12"; an empty topic,
/// "run.bag::12", means the bag's only PointCloud2 topic). INDEX counts from 0 in the order of
/// the bag's messages on the topic.
struct BagScanReference {
    std::filesystem::path bag;
    std::string topic;
    std::size_t index = 0;
};

/// The reference `text` names, or nothing when `text` is no "FILE.bag:TOPIC:INDEX". ReadError
/// when it names a bag but INDEX is not a number.
std::optional<BagScanReference> ParseBagScanReference(const std::string& text);

/// "BAG:TOPIC:INDEX".
std::string ToString(const BagScanReference& reference);

/// The sensor_msgs/PointCloud2 messages of one topic of a bag, read on demand: opening reads the
/// bag's index and each message's header stamp once (one pass over the topic, nothing kept but
/// the index and the stamps); Load(i) reads message i again. Thread-safe: reads of the bag are
/// serialised, decoding is not.
class BagScans {
public:
    /// Opens `bag` on `topic`; an empty topic picks the bag's only PointCloud2 topic. ReadError
    /// naming the file (and the topic) for a missing, truncated or corrupt bag, a topic that is
    /// absent (listing the PointCloud2 topics), of another type or without messages, an empty
    /// topic when the bag has no or several PointCloud2 topics (listing them), and a message
    /// too short to hold a header.
    static std::shared_ptr<const BagScans> Open(const std::filesystem::path& bag,
                                                const std::string& topic = {});
    ~BagScans();
    BagScans(const BagScans&) = delete;
    BagScans& operator=(const BagScans&) = delete;

    const std::filesystem::path& file() const;
    const std::string& topic() const;
    std::size_t size() const;
    /// Header stamp of each message, seconds (not necessarily increasing).
    const std::vector<double>& times_s() const;
    /// The points of message `index` (core::PointCloud; non-finite points dropped). ReadError
    /// naming the file, the topic and the message for a cloud that cannot be decoded
    /// (DecodePointCloud2) or read; std::out_of_range for an index past size().
    core::PointCloud Load(std::size_t index) const;

private:
    struct Impl;
    explicit BagScans(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

/// The scan a reference names (BagScans::Open and Load; ReadError for an index past the topic's
/// messages).
core::PointCloud ReadBagScan(const BagScanReference& reference);

/// Odometry for scans at `scan_times_s` from the nav_msgs/Odometry messages of `topic` in `bag`
/// (header stamps; pose.pose as T_world_sensor): per scan, the odometry interpolated at its time
/// (linearly in position, slerp in rotation; a message at the scan's very time is taken as it
/// is). ReadError naming the file and the topic when the topic is absent, of another type or
/// empty, a message cannot be decoded, two messages have the same stamp, a scan lies outside
/// the odometry's times (giving both spans), or one pose lies more than `max_step_m` from the
/// one before (a jump or a reset).
std::vector<core::StampedPose> ReadBagOdometry(
    const std::filesystem::path& bag, const std::string& topic,
    const std::vector<double>& scan_times_s,
    double max_step_m = std::numeric_limits<double>::infinity());

}  // namespace lidarloop::io

#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// Layouts of a sequence of scans on disk.
enum class DatasetFormat {
    kAuto,        ///< detect from the folder's content
    kKitti,       ///< KITTI odometry: velodyne/*.bin, optional poses.txt, calib.txt, times.txt
    kFolder,      ///< a folder of .pcd/.ply/.xyz/.txt/.pts/.bin files, sorted by name
    kOsnabrueck,  ///< Osnabrück repository: scanNNN.3d with scanNNN.pose or scanNNN.frames
    kRosbag,      ///< a ROS 1 bag (.bag file): the sensor_msgs/PointCloud2 messages of one topic
};

class BagScans;

/// How to open a dataset. Empty paths mean "look in the usual place".
struct DatasetOptions {
    DatasetFormat format = DatasetFormat::kAuto;
    std::filesystem::path poses_file;  ///< KITTI poses.txt or TUM file (detected by its content)
    std::filesystem::path calib_file;  ///< KITTI calib.txt; default: calib.txt beside the scans
    /// A bag's PointCloud2 topic; empty: the bag's only one. An error for a folder.
    std::string topic;
};

/// An ordered sequence of scans with optional ground-truth poses. Scans are loaded on demand;
/// LoadScan is thread-safe (it only reads files, or a bag under a lock).
class Dataset {
public:
    /// `times_s`: the scans' times (s) when there are no poses (a times.txt), else empty.
    Dataset(DatasetFormat format, std::filesystem::path root,
            std::vector<std::filesystem::path> scan_files, std::vector<core::StampedPose> poses,
            std::vector<double> times_s = {});
    /// The scans of a bag's topic; `poses` one per scan or none.
    Dataset(std::shared_ptr<const BagScans> bag, std::vector<core::StampedPose> poses);

    DatasetFormat format() const { return format_; }
    std::string FormatName() const;
    /// The folder, or the bag file.
    const std::filesystem::path& root() const { return root_; }
    std::size_t size() const { return scan_files_.size(); }
    /// The scan's file, or for a bag its reference "BAG:TOPIC:INDEX" (io::ReadScan reads both).
    const std::filesystem::path& ScanPath(std::size_t index) const;
    const std::vector<std::filesystem::path>& ScanPaths() const { return scan_files_; }
    core::PointCloud LoadScan(std::size_t index) const;
    bool HasPoses() const { return !poses_.empty(); }
    /// True when the scans have recording times: poses (with their times), a times.txt or a
    /// bag's stamps.
    bool HasTimes() const { return HasPoses() || !times_s_.empty() || bag_ != nullptr; }
    /// Recording time of a scan, seconds: a bag message's header stamp, else its pose's time,
    /// else its line of times.txt, else its index.
    double ScanTime(std::size_t index) const;
    /// The bag's topic ("" for a folder).
    std::string Topic() const;
    /// One pose per scan (T_world_sensor); empty when the dataset has none.
    const std::vector<core::StampedPose>& poses() const { return poses_; }
    /// What was read to open it, which no output may replace or lie inside: the folder or bag,
    /// and the poses and calibration files given for it (OpenDataset; set_given_files).
    std::vector<std::filesystem::path> InputFiles() const;
    void set_given_files(std::vector<std::filesystem::path> files) {
        given_files_ = std::move(files);
    }

private:
    DatasetFormat format_;
    std::filesystem::path root_;
    std::vector<std::filesystem::path> scan_files_;
    std::vector<core::StampedPose> poses_;
    std::vector<double> times_s_;                     ///< without poses: times.txt's, one a scan
    std::shared_ptr<const BagScans> bag_;             ///< for kRosbag
    std::vector<std::filesystem::path> given_files_;  ///< poses and calib files named for it
};

/// Opens a dataset folder, detecting its format unless `options.format` names one, or a ROS 1 bag
/// (a .bag file; BagScans::Open on `options.topic`; poses from `options.poses_file` only, a KITTI
/// file's times being the scans' stamps). Throws ReadError when the path does not exist, holds
/// no scans, the format cannot be told (the message says what was looked for), the number of
/// poses differs from the number of scans, or a topic is given for a folder.
Dataset OpenDataset(const std::filesystem::path& path, const DatasetOptions& options = {});

/// A KITTI sequence's scans may be some of its frames (velodyne/000094.bin is frame 94) with a
/// KITTI file of one pose per frame of the whole drive: when `poses` holds more poses than there
/// are `scans`, `poses_file` is no TUM file, every scan's name is a frame number and the scans
/// are not frames 0 to n - 1 (a whole sequence, whose file holds one pose a scan), the poses of
/// those frames, in the scans' order, each with the drive's path to it
/// (core::StampedPose::path_m); otherwise `poses` as given. ReadError naming `poses_file` when a
/// scan's frame lies beyond its poses, or naming a scan whose frame the one before has too.
std::vector<core::StampedPose> PosesOfFrames(const std::vector<std::filesystem::path>& scans,
                                             std::vector<core::StampedPose> poses,
                                             const std::filesystem::path& poses_file);

/// Why PosesOfFrames kept `poses` poses for `scans` (KITTI layout), for a count mismatch's
/// message: a scan not named by a frame number, frames 0 to n - 1, or else a TUM file; "" when
/// there are no more poses than scans.
std::string PosesOfFramesHint(const std::vector<std::filesystem::path>& scans, std::size_t poses);

/// What a run tells its user when PosesOfFrames took `poses` (named `what`: "poses", "odometry")
/// by the scans' frame numbers: which frames, so that another drive's file is seen; empty when
/// the poses are one a scan as given.
std::string FramesNote(const std::vector<std::filesystem::path>& scans,
                       const std::vector<core::StampedPose>& poses, const std::string& what);

}  // namespace lidarloop::io

#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// Writes a sequence in the KITTI odometry layout, streaming: DIR/velodyne/NNNNNN.bin (six
/// digits, float32 x y z intensity with intensity 0), DIR/poses.txt (T_world_sensor per scan,
/// 3x4 row-major, already in the LiDAR frame, so no calib.txt is written), DIR/times.txt (seconds,
/// one per line) and, when odometry poses are given, DIR/poses_odometry.txt (same format as
/// poses.txt). io::OpenDataset reads the result as a KITTI dataset with ground-truth poses.
class KittiSequenceWriter {
public:
    /// Creates DIR and DIR/velodyne, opens (truncates) poses.txt and times.txt and removes a
    /// poses_odometry.txt of an earlier run. Throws WriteError when they cannot be created, or
    /// when DIR/velodyne already holds .bin files and `overwrite` is false: stale scans of an
    /// older, longer sequence would be read with the new poses. With `overwrite` the .bin files
    /// in DIR/velodyne are deleted first; no other file is touched.
    explicit KittiSequenceWriter(const std::filesystem::path& dir, bool overwrite = false);

    /// DIR/velodyne/<index as 6 digits>.bin
    std::filesystem::path ScanPath(std::size_t index) const;

    /// Writes scan `index`. Thread-safe for distinct indices, in any order. Throws WriteError.
    void WriteScan(std::size_t index, const core::PointCloud& cloud) const;

    /// Appends the ground-truth pose and time of the next scan (scan order). Not thread-safe.
    void AppendPose(const core::StampedPose& ground_truth);
    /// Appends the odometry pose of the next scan to poses_odometry.txt (scan order).
    void AppendOdometryPose(const core::StampedPose& odometry);

    /// Closes the pose files. Throws WriteError when a write failed, or when odometry poses were
    /// given for some scans but not for all.
    void Finish();

    std::size_t poses_written() const { return poses_; }
    const std::filesystem::path& dir() const { return dir_; }

private:
    std::filesystem::path dir_;
    std::ofstream poses_out_;
    std::ofstream times_out_;
    std::ofstream odometry_out_;
    std::size_t poses_ = 0;
    std::size_t odometry_poses_ = 0;
};

}  // namespace lidarloop::io

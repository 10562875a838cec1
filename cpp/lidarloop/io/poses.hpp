#pragma once

#include <filesystem>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// Reads the `Tr:` line (velodyne -> camera 0, 3x4 row-major) of a KITTI odometry `calib.txt`
/// and returns T_cam0_velo. Throws ReadError when the line is missing or malformed.
core::Transform ReadKittiCalibTr(const std::filesystem::path& calib_file);

/// Reads a KITTI odometry `poses.txt`: one 3x4 row-major matrix (12 numbers) per line giving
/// T_cam0first_cam0i. With `T_cam0_velo` (from calib.txt) the poses are converted to the LiDAR
/// frame, T_velo0_veloi = T_cam0_velo^-1 * P_i * T_cam0_velo; with identity they are taken as
/// given (files written by lidarloop's simulator are already in the LiDAR frame). time_s is the
/// line index unless `times_file` (KITTI `times.txt`, one number per line) is given.
/// Throws ReadError naming the line with the wrong number of values or a non-number.
std::vector<core::StampedPose> ReadKittiPoses(
    const std::filesystem::path& poses_file,
    const core::Transform& T_cam0_velo = core::Transform::Identity(),
    const std::filesystem::path& times_file = {});

/// Writes poses as KITTI `poses.txt` (T_world_sensor, 3x4 row-major, no calibration applied).
void WriteKittiPoses(const std::filesystem::path& poses_file,
                     const std::vector<core::StampedPose>& poses);

/// Reads a TUM trajectory: lines "timestamp tx ty tz qx qy qz qw" (metres, Hamilton quaternion
/// of T_world_sensor); '#' comment lines skipped. Quaternions are normalised; one whose norm is
/// far from 1 (< 0.9 or > 1.1) or zero is an error naming the line.
std::vector<core::StampedPose> ReadTumPoses(const std::filesystem::path& file);

/// Writes poses in TUM format.
void WriteTumPoses(const std::filesystem::path& file, const std::vector<core::StampedPose>& poses);

}  // namespace lidarloop::io

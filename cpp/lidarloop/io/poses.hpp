#pragma once

#include <filesystem>
#include <limits>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// Reads the `Tr:` line (velodyne -> camera 0, 3x4 row-major) of a KITTI odometry `calib.txt`
/// and returns T_cam0_velo. Other lines (P0: ... P3:) are not read. Throws ReadError when the line
/// is missing (also for an empty file), malformed (not 12 finite numbers, not a rotation) or
/// repeated (which one is meant cannot be told).
core::Transform ReadKittiCalibTr(const std::filesystem::path& calib_file);

/// Reads a KITTI odometry `poses.txt`: one 3x4 row-major matrix (12 numbers) per line giving
/// T_cam0first_cam0i. With `T_cam0_velo` (from calib.txt) the poses are converted to the LiDAR
/// frame, T_velo0_veloi = T_cam0_velo^-1 * P_i * T_cam0_velo; with identity they are taken as
/// given (files written by lidarloop's simulator are already in the LiDAR frame). time_s is the
/// line index unless `times_file` (KITTI `times.txt`, one number per line) is given.
/// Blank and '#' lines are skipped; an empty file gives no poses. Rotations within 1e-3 of
/// orthonormal are snapped to the nearest rotation. Throws ReadError naming the line with the
/// wrong number of values, a non-number, a non-finite value, a 3x3 part that is no rotation, a
/// position more than 1e8 m from the origin (no Earth-fixed frame has one) and a time in
/// times.txt that does not increase; and when times.txt holds another count of times than there
/// are poses. Identical consecutive poses (a standing vehicle) are legal.
std::vector<core::StampedPose> ReadKittiPoses(
    const std::filesystem::path& poses_file,
    const core::Transform& T_cam0_velo = core::Transform::Identity(),
    const std::filesystem::path& times_file = {});

/// Reads a KITTI `times.txt`: one time a line, seconds. Blank and '#' lines are skipped. Throws
/// ReadError naming the line with another count of values, a non-number, a non-finite value or
/// a time that does not increase.
std::vector<double> ReadKittiTimes(const std::filesystem::path& times_file);

/// Writes poses as KITTI `poses.txt` (T_world_sensor, 3x4 row-major, no calibration applied,
/// full double precision). Times are not written.
void WriteKittiPoses(const std::filesystem::path& poses_file,
                     const std::vector<core::StampedPose>& poses);

/// Reads a TUM trajectory: lines "timestamp tx ty tz qx qy qz qw" (metres, Hamilton quaternion
/// of T_world_sensor); blank and '#' comment lines skipped, an empty file gives no poses.
/// Quaternions are normalised; one whose norm is far from 1 (< 0.9 or > 1.1) or zero is an error
/// naming the line, as are a line without exactly 8 values, a non-number, a non-finite value, a
/// timestamp that does not increase (repeated or going back), and a position more than 1e8 m
/// from the origin.
std::vector<core::StampedPose> ReadTumPoses(const std::filesystem::path& file);

/// Reads a KITTI (12 numbers a line) or TUM (8 numbers a line) poses file, told apart by its
/// first data line; `T_cam0_velo` and `times_file` apply to KITTI files as in ReadKittiPoses.
/// ReadError naming the line when the first data line has another count of numbers, and, for
/// odometry, for a position more than `max_step_m` from the one before (a jump or a reset; the
/// default checks none, since a ground truth may be sparse).
std::vector<core::StampedPose> ReadPoses(
    const std::filesystem::path& file,
    const core::Transform& T_cam0_velo = core::Transform::Identity(),
    const std::filesystem::path& times_file = {},
    double max_step_m = std::numeric_limits<double>::infinity());

/// True when the first data line of `file` has 8 numbers (TUM: poses with their times); ReadError
/// when the file cannot be read.
bool IsTumPosesFile(const std::filesystem::path& file);

/// Writes poses in TUM format (full double precision).
void WriteTumPoses(const std::filesystem::path& file, const std::vector<core::StampedPose>& poses);

}  // namespace lidarloop::io

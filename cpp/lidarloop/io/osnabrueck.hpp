#pragma once

#include <filesystem>

#include <Eigen/Core>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// The Osnabrück Robotic 3D Scan Repository (3DTK/slam6D) stores points and poses in a
/// left-handed frame with y up and z forward, in centimetres. lidarloop uses a right-handed frame
/// with x forward, y left, z up, in metres:
///     x_ll = z_3dtk / 100,  y_ll = -x_3dtk / 100,  z_ll = y_3dtk / 100.
/// This map has determinant -1, which is exactly what turns the left-handed frame right-handed.
Eigen::Vector3d FromOsnabrueckCoordinates(const Eigen::Vector3d& p_3dtk_cm);

/// Inverse of FromOsnabrueckCoordinates.
Eigen::Vector3d ToOsnabrueckCoordinates(const Eigen::Vector3d& p_m);

/// Reads a `scanNNN.3d` file: text lines with at least x y z (further columns such as
/// reflectance are ignored), converted to lidarloop's frame and metres. An optional first line
/// of the form "W x H" (as some scans carry), blank lines and '#' comment lines are skipped;
/// "nan" coordinates are kept as NaN. A file without points gives an empty cloud. Throws
/// ReadError naming the line with fewer than three numbers, a non-number or binary data.
core::PointCloud ReadOsnabrueck3d(const std::filesystem::path& file);

/// Writes `cloud` as a `scanNNN.3d` file (3DTK frame, centimetres).
void WriteOsnabrueck3d(const std::filesystem::path& file, const core::PointCloud& cloud);

/// Reads a `scanNNN.pose` file (line 1: position x y z in cm; line 2: Euler angles rx ry rz in
/// degrees, 3DTK convention R = Rx(rx) Ry(ry) Rz(rz) acting on 3DTK column vectors) and returns
/// T_world_sensor in lidarloop's frame and metres. Like 3DTK, only the count of six numbers
/// matters, not the line breaks. Throws ReadError for an empty file, another count, a non-number
/// or a non-finite value.
core::Transform ReadOsnabrueckPose(const std::filesystem::path& file);

/// Writes T_world_sensor (lidarloop frame) as a `scanNNN.pose` file (full double precision).
void WriteOsnabrueckPose(const std::filesystem::path& file, const core::Transform& T_world_sensor);

/// Reads a `scanNNN.frames` file (one 4x4 column-major matrix of 16 numbers plus a colour code per
/// line, 3DTK frame, cm) and returns the last, final pose as T_world_sensor in lidarloop's frame.
/// Every line is checked: 16 or 17 finite numbers, bottom row 0 0 0 1, and a 3x3 part within
/// 1e-3 of a rotation (it is snapped to the nearest rotation). Throws ReadError naming the bad
/// line, or when the file holds no frames.
core::Transform ReadOsnabrueckFrames(const std::filesystem::path& file);

}  // namespace lidarloop::io

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
/// of the form "W x H" (as some scans carry) is skipped. Throws ReadError naming a bad line.
core::PointCloud ReadOsnabrueck3d(const std::filesystem::path& file);

/// Writes `cloud` as a `scanNNN.3d` file (3DTK frame, centimetres).
void WriteOsnabrueck3d(const std::filesystem::path& file, const core::PointCloud& cloud);

/// Reads a `scanNNN.pose` file (line 1: position x y z in cm; line 2: Euler angles rx ry rz in
/// degrees, 3DTK convention) and returns T_world_sensor in lidarloop's frame and metres.
core::Transform ReadOsnabrueckPose(const std::filesystem::path& file);

/// Writes T_world_sensor (lidarloop frame) as a `scanNNN.pose` file.
void WriteOsnabrueckPose(const std::filesystem::path& file, const core::Transform& T_world_sensor);

/// Reads a `scanNNN.frames` file (one 4x4 column-major matrix of 16 numbers plus a colour code per
/// line, 3DTK frame, cm) and returns the last, final pose as T_world_sensor in lidarloop's frame.
core::Transform ReadOsnabrueckFrames(const std::filesystem::path& file);

}  // namespace lidarloop::io

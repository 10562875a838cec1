#pragma once

#include <filesystem>
#include <string>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// True when ReadScan knows the file's extension (.bin, .pcd, .ply, .xyz, .txt, .pts, .3d).
bool IsScanFile(const std::filesystem::path& file);

/// True for a text file that holds poses, times or calibration, not points: a .txt whose name
/// begins with poses, times or calib (KITTI's names and their variants: poses_odometry.txt,
/// calib_00.txt).
bool IsSidecarFile(const std::filesystem::path& file);

/// Reads one scan, choosing the reader by the file extension (case-insensitive), or the message a
/// bag scan reference "BAG:TOPIC:INDEX" names (rosbag.hpp). Throws ReadError for a missing file,
/// an unknown extension (listing the known ones), a file named as poses, times or calibration
/// (IsSidecarFile; its lines would read as points) or bad content.
core::PointCloud ReadScan(const std::filesystem::path& file);

}  // namespace lidarloop::io

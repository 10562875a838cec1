#pragma once

#include <filesystem>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// Reads a KITTI Velodyne scan: consecutive little-endian float32 records (x, y, z, intensity),
/// metres, sensor frame. Intensity is dropped. Throws ReadError when the file cannot be opened or
/// its size is not a multiple of 16 bytes (truncated or not a KITTI scan), and when it starts
/// with a PCD or PLY text header. An empty file gives an empty cloud (the descriptor, not the
/// reader, decides whether that is an error). Non-finite values are kept.
core::PointCloud ReadKittiBin(const std::filesystem::path& file);

/// Writes `cloud` as a KITTI Velodyne scan with intensity 0.
void WriteKittiBin(const std::filesystem::path& file, const core::PointCloud& cloud);

}  // namespace lidarloop::io

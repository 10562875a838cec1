#pragma once

#include <filesystem>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// Data encodings of the PCD v0.7 format (Point Cloud Library).
enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };

/// Reads the x, y, z fields of a PCD v0.5–v0.7 file in any of its three encodings. Fields may be
/// float32 or float64 (F 4 / F 8); other fields (intensity, rgb, ...) of any type and COUNT are
/// skipped. NaN points (no return in organised clouds) are kept. Throws ReadError naming the
/// header line or data record that is wrong: missing or non-float x/y/z, unknown DATA type,
/// POINTS inconsistent with WIDTH*HEIGHT, truncated data, corrupt LZF block.
core::PointCloud ReadPcd(const std::filesystem::path& file);

/// Writes `cloud` as PCD v0.7 with FIELDS x y z (float32) in the given encoding.
void WritePcd(const std::filesystem::path& file, const core::PointCloud& cloud,
              PcdEncoding encoding);

}  // namespace lidarloop::io

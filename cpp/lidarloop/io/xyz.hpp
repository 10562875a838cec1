#pragma once

#include <filesystem>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// Reads a plain text point file: one point per line, at least three numbers (x y z, metres)
/// separated by spaces, tabs or commas; further columns are ignored. Blank lines and lines
/// starting with '#' or '//' are skipped, and so is a first data line holding one integer only
/// (the point count of Leica .pts files). "nan"/"inf" are accepted and kept as non-finite. A file
/// without points (empty, or only comments) gives an empty cloud.
/// Throws ReadError naming the line that has fewer than three numbers, a non-number or a control
/// character (binary input).
core::PointCloud ReadXyz(const std::filesystem::path& file);

/// Writes `cloud` as "x y z" lines with enough digits to round-trip float32 exactly.
void WriteXyz(const std::filesystem::path& file, const core::PointCloud& cloud);

}  // namespace lidarloop::io

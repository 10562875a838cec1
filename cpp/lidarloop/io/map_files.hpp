#pragma once

#include <filesystem>

#include "lidarloop/core/point_map.hpp"

namespace lidarloop::io {

/// Writes `map` as a binary little-endian PLY 1.0 file with one `vertex` element: x, y, z (float;
/// double when a coordinate lies more than 1e5 m from the origin, where a float keeps less than a
/// centimetre), red, green, blue (uchar: Viridis of the point's time between the map's first and
/// last scan time, 0.5 when they are equal) and time (double, the mean scan time of the voxel,
/// seconds). Header comments say "written by lidarloop", the scans, the voxel edge and the colour
/// scale. ReadPly reads it back (x, y, z). Throws WriteError.
void WriteMapPly(const std::filesystem::path& file, const core::MapCloud& map);

/// True when `file` is a PLY file whose header holds lidarloop's "comment written by lidarloop"
/// (a file a lidarloop command may replace without --overwrite). Never throws.
bool IsLidarloopPly(const std::filesystem::path& file);

/// The map's colour scale position of `time_s`: 0 at map.first_time_s, 1 at map.last_time_s,
/// 0.5 when they are equal.
double MapTimeFraction(const core::MapCloud& map, double time_s);

}  // namespace lidarloop::io

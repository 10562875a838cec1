#pragma once

#include <filesystem>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// Data encodings of the PCD v0.7 format (Point Cloud Library).
enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };

/// Reads the x, y, z fields of a PCD v0.5–v0.7 file in any of its three encodings (ascii, binary
/// little-endian records, binary_compressed: LZF block of field-major values, padding fields "_"
/// left out as PCL writes them). Coordinates may be float32 or float64 (F 4 / F 8; doubles are
/// rounded to float); other fields (intensity, rgb, ...) of any TYPE, SIZE 1/2/4/8 and COUNT are
/// skipped. VERSION and COUNT lines are optional, VIEWPOINT is ignored (points stay as stored).
/// NaN points (no return in organised clouds) are kept, in the file's order.
///
/// Throws ReadError "<file>: <problem>" naming the header line or data line that is wrong:
/// missing file, unknown header keyword, missing DATA/FIELDS/SIZE/TYPE/POINTS line, unknown DATA
/// type, missing or non-float x/y/z, SIZE/TYPE/COUNT lengths unlike FIELDS, POINTS unlike
/// WIDTH*HEIGHT, truncated data (bytes needed vs present), corrupt or mis-sized LZF block, ascii
/// lines with a wrong number of values or a non-number. Sizes from the header are checked against
/// the file size before anything is allocated. Thread-safe for distinct files.
core::PointCloud ReadPcd(const std::filesystem::path& file);

/// Writes `cloud` as PCD v0.7 with FIELDS x y z (float32), WIDTH = POINTS = cloud.size(),
/// HEIGHT 1, in the given encoding; non-finite points are written as they are. Ascii uses 9
/// significant digits, so ReadPcd gives back the exact floats in every encoding. Throws
/// WriteError when the file cannot be written (or, for binary_compressed, when the cloud exceeds
/// the 4 GiB the format's uint32 sizes can describe).
void WritePcd(const std::filesystem::path& file, const core::PointCloud& cloud,
              PcdEncoding encoding);

}  // namespace lidarloop::io

#pragma once

#include <filesystem>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// Storage formats of the PLY format.
enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

/// Scalar type used for the vertex coordinates when writing.
enum class PlyScalar { kFloat32, kFloat64 };

/// Reads the x, y, z properties of the `vertex` element of a PLY 1.0 file (ascii, binary little
/// or big endian). Coordinates must be float/float32 or double/float64 (doubles are rounded to
/// float); integer coordinates are rejected, as they usually carry a scale the file does not
/// state. Other vertex properties of any scalar type are skipped, as are other elements before or
/// after the vertices, list properties included. In ascii files every element item is one line.
///
/// Throws ReadError "<file>: <problem>" naming the header line, the vertex (and for ascii the
/// line) that is wrong: missing file, no "ply" magic, unknown format or keyword, unknown type, no
/// vertex element or no x/y/z, non-float coordinates, truncated binary data, element counts that
/// the file size cannot hold (checked before allocating), ascii vertices with too few or too many
/// values or a non-number. Thread-safe for distinct files.
core::PointCloud ReadPly(const std::filesystem::path& file);

/// Writes `cloud` as a PLY 1.0 file with a single `vertex` element holding x, y, z as float or
/// double; non-finite points are written as they are. Ascii uses max_digits10 significant digits,
/// so ReadPly gives back the exact floats in every encoding. Throws WriteError on failure.
void WritePly(const std::filesystem::path& file, const core::PointCloud& cloud,
              PlyEncoding encoding, PlyScalar scalar);

}  // namespace lidarloop::io

#pragma once

#include <filesystem>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// Storage formats of the PLY format.
enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

/// Scalar type used for the vertex coordinates when writing.
enum class PlyScalar { kFloat32, kFloat64 };

/// Reads the x, y, z properties of the `vertex` element of a PLY file (ascii, binary little or
/// big endian). Coordinates may be float/float32 or double/float64; other vertex properties of
/// any scalar type are skipped, as are other elements (faces with list properties included).
/// Throws ReadError naming the header line or the vertex that is wrong.
core::PointCloud ReadPly(const std::filesystem::path& file);

/// Writes `cloud` as a PLY file with a single `vertex` element holding x, y, z.
void WritePly(const std::filesystem::path& file, const core::PointCloud& cloud,
              PlyEncoding encoding, PlyScalar scalar);

}  // namespace lidarloop::io

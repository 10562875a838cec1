#pragma once

// Internal helpers shared by the readers and writers of binary formats (KITTI .bin, PCD, PLY).
// Not installed as public API promise.

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "lidarloop/core/byte_codec.hpp"

namespace lidarloop::io::detail {

using core::CheckedMul;
using core::Load;
using core::LoadLittle;
using core::Store;
using core::StoreLittle;

/// A byte count for a message: the number, or "more than <SIZE_MAX>" where CheckedMul overflowed.
std::string BytesText(std::optional<std::size_t> bytes);

/// Size of `file` in bytes; throws ReadError "cannot get the file size (<reason>)".
std::size_t FileSize(const std::filesystem::path& file);

/// The whole content of `file`; ReadError when it cannot be opened or read.
std::string ReadWholeFile(const std::filesystem::path& file);

/// Replaces `file` by `bytes`; WriteError when it cannot be written.
void WriteWholeFile(const std::filesystem::path& file, const std::string& bytes);

/// Rounds a double to float as IEEE does, also beyond the float range, where a plain narrowing
/// conversion is undefined behaviour: up to half an ulp above FLT_MAX rounds down to it (9-digit
/// text of FLT_MAX reads back as such a value), from there on to infinity. NaN stays NaN.
inline float ToFloat(double value) {
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    if (std::isnan(value) || std::abs(value) <= kFloatMax) return static_cast<float>(value);
    const double overflow = std::ldexp(1.0, 128) - std::ldexp(1.0, 103);  // FLT_MAX + ulp / 2
    const float magnitude = std::abs(value) < overflow ? std::numeric_limits<float>::max()
                                                       : std::numeric_limits<float>::infinity();
    return value > 0 ? magnitude : -magnitude;
}

/// The binary data of a file that starts with a text header, and the number of bytes left in it.
struct DataStream {
    std::ifstream in;
    std::size_t remaining = 0;
};

/// Opens `file` for binary reading positioned after its first `header_lines` lines.
DataStream OpenDataAfterHeader(const std::filesystem::path& file, std::size_t header_lines);

/// Reads the next `count` bytes, which the caller has checked against `data.remaining`; throws
/// ReadError "read failed after <n> of <count> data bytes" when the read comes up short.
std::vector<char> ReadDataBytes(const std::filesystem::path& file, DataStream& data,
                                std::size_t count);

}  // namespace lidarloop::io::detail

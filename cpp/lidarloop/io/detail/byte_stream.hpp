#pragma once

// lidarloop's own binary files (similarity matrix, database): core's little-endian codec with
// errors that name the file.

#include <filesystem>
#include <string>

#include "lidarloop/core/byte_codec.hpp"
#include "lidarloop/io/detail/binary_io.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io::detail {

using core::ByteWriter;

/// A reader of `data`, the content of `file`, whose failures are ReadErrors naming `file`.
inline core::ByteReader FileReader(const std::filesystem::path& file, std::string data) {
    return core::ByteReader(std::move(data),
                            [file](const std::string& problem) { throw ReadError(file, problem); });
}

}  // namespace lidarloop::io::detail

#include "lidarloop/io/kitti_bin.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/text_parsing.hpp"

namespace lidarloop::io {
namespace {

constexpr std::size_t kFloatBytes = 4;
constexpr std::size_t kRecordBytes = 4 * kFloatBytes;  // x, y, z, intensity

// Assembling the value from bytes is correct on any host byte order, has no alignment or
// aliasing UB, and compiles to a single load on little-endian machines.
float LoadFloatLittleEndian(const unsigned char* bytes) {
    const std::uint32_t bits = std::uint32_t{bytes[0]} | (std::uint32_t{bytes[1]} << 8) |
                               (std::uint32_t{bytes[2]} << 16) | (std::uint32_t{bytes[3]} << 24);
    return std::bit_cast<float>(bits);
}

void StoreFloatLittleEndian(float value, unsigned char* bytes) {
    const auto bits = std::bit_cast<std::uint32_t>(value);
    for (std::size_t i = 0; i < kFloatBytes; ++i) {
        bytes[i] = static_cast<unsigned char>(bits >> (8 * i));
    }
}

// A text header where float records are expected means another format with a .bin name; real
// KITTI coordinates never spell these bytes (they would be values like 1e-32 m or 1e10 m).
void RejectKnownTextHeaders(const std::filesystem::path& file,
                            const std::vector<unsigned char>& bytes) {
    const std::string_view start(reinterpret_cast<const char*>(bytes.data()),
                                 std::min<std::size_t>(bytes.size(), 16));
    if (start.starts_with("# .PCD") || start.starts_with("VERSION")) {
        throw ReadError(file, "starts with a PCD header; this is not a KITTI scan");
    }
    if (start.starts_with("ply\n") || start.starts_with("ply\r\n")) {
        throw ReadError(file, "starts with a PLY header; this is not a KITTI scan");
    }
}

std::vector<unsigned char> ReadAllBytes(const std::filesystem::path& file) {
    std::ifstream in = detail::OpenForReading(file, /*binary=*/true);
    std::error_code ec;
    const auto size = std::filesystem::file_size(file, ec);
    if (ec) throw ReadError(file, "cannot get the file size (" + ec.message() + ")");
    if (size % kRecordBytes != 0) {
        throw ReadError(file, "size " + std::to_string(size) +
                                  " bytes is not a multiple of 16 (float32 x, y, z, intensity): "
                                  "truncated or not a KITTI scan");
    }
    std::vector<unsigned char> bytes(size);
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
    if (static_cast<std::uintmax_t>(in.gcount()) != size) {
        throw ReadError(file, "read " + std::to_string(in.gcount()) + " of " +
                                  std::to_string(size) + " bytes (file changed or I/O error)");
    }
    return bytes;
}

}  // namespace

core::PointCloud ReadKittiBin(const std::filesystem::path& file) {
    const std::vector<unsigned char> bytes = ReadAllBytes(file);
    RejectKnownTextHeaders(file, bytes);
    core::PointCloud cloud(bytes.size() / kRecordBytes);
    const unsigned char* record = bytes.data();
    for (auto& point : cloud) {
        point = {LoadFloatLittleEndian(record), LoadFloatLittleEndian(record + kFloatBytes),
                 LoadFloatLittleEndian(record + 2 * kFloatBytes)};
        record += kRecordBytes;
    }
    return cloud;
}

void WriteKittiBin(const std::filesystem::path& file, const core::PointCloud& cloud) {
    std::vector<unsigned char> bytes(cloud.size() * kRecordBytes);
    unsigned char* record = bytes.data();
    for (const auto& point : cloud) {
        for (std::size_t axis = 0; axis < 3; ++axis) {
            StoreFloatLittleEndian(point[axis], record + axis * kFloatBytes);
        }
        StoreFloatLittleEndian(0.0f, record + 3 * kFloatBytes);  // intensity
        record += kRecordBytes;
    }
    std::ofstream out = detail::OpenForWriting(file, /*binary=*/true);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw WriteError(file, "writing " + std::to_string(bytes.size()) + " bytes failed");
}

}  // namespace lidarloop::io

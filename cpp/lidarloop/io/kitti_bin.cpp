#include "lidarloop/io/kitti_bin.hpp"

#include <algorithm>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "lidarloop/io/detail/binary_io.hpp"
#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {
namespace {

using detail::LoadLittle;
using detail::StoreLittle;

constexpr std::size_t kFloatBytes = 4;
constexpr std::size_t kRecordBytes = 4 * kFloatBytes;  // x, y, z, intensity

// A text header where float records are expected means another format with a .bin name; real
// KITTI coordinates never spell these bytes (they would be values like 1e-32 m or 1e10 m).
void RejectKnownTextHeaders(const std::filesystem::path& file, const std::vector<char>& bytes) {
    const std::string_view start(bytes.data(), std::min<std::size_t>(bytes.size(), 16));
    if (start.starts_with("# .PCD") || start.starts_with("VERSION")) {
        throw ReadError(file, "starts with a PCD header; this is not a KITTI scan");
    }
    if (start.starts_with("ply\n") || start.starts_with("ply\r\n")) {
        throw ReadError(file, "starts with a PLY header; this is not a KITTI scan");
    }
}

std::vector<char> ReadAllBytes(const std::filesystem::path& file) {
    std::ifstream in = detail::OpenForReading(file, /*binary=*/true);
    const std::size_t size = detail::FileSize(file);
    if (size % kRecordBytes != 0) {
        throw ReadError(file, "size " + std::to_string(size) +
                                  " bytes is not a multiple of 16 (float32 x, y, z, intensity): "
                                  "truncated or not a KITTI scan");
    }
    std::vector<char> bytes(size);
    in.read(bytes.data(), static_cast<std::streamsize>(size));
    if (static_cast<std::size_t>(in.gcount()) != size) {
        throw ReadError(file, "read " + std::to_string(in.gcount()) + " of " +
                                  std::to_string(size) + " bytes (file changed or I/O error)");
    }
    return bytes;
}

}  // namespace

core::PointCloud ReadKittiBin(const std::filesystem::path& file) {
    const std::vector<char> bytes = ReadAllBytes(file);
    RejectKnownTextHeaders(file, bytes);
    core::PointCloud cloud(bytes.size() / kRecordBytes);
    const char* record = bytes.data();
    for (auto& point : cloud) {
        point = {LoadLittle<float>(record), LoadLittle<float>(record + kFloatBytes),
                 LoadLittle<float>(record + 2 * kFloatBytes)};
        record += kRecordBytes;
    }
    return cloud;
}

void WriteKittiBin(const std::filesystem::path& file, const core::PointCloud& cloud) {
    std::vector<char> bytes(cloud.size() * kRecordBytes);
    char* record = bytes.data();
    for (const auto& point : cloud) {
        for (std::size_t axis = 0; axis < 3; ++axis) {
            StoreLittle(point[axis], record + axis * kFloatBytes);
        }
        StoreLittle(0.0f, record + 3 * kFloatBytes);  // intensity
        record += kRecordBytes;
    }
    std::ofstream out = detail::OpenForWriting(file, /*binary=*/true);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw WriteError(file, "writing " + std::to_string(bytes.size()) + " bytes failed");
}

}  // namespace lidarloop::io

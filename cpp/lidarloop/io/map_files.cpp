#include "lidarloop/io/map_files.hpp"

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "lidarloop/io/colour_map.hpp"
#include "lidarloop/io/detail/binary_io.hpp"
#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {
namespace {

constexpr char kLidarloopComment[] = "comment written by lidarloop";
// Beyond this a float's spacing exceeds 7.8 mm.
constexpr double kFloatLimitM = 1e5;

bool NeedsDoubles(const core::MapCloud& map) {
    for (const core::MapPoint& point : map.points) {
        if (point.position.cwiseAbs().maxCoeff() > kFloatLimitM) return true;
    }
    return false;
}

void WriteHeader(std::ostream& out, const core::MapCloud& map, bool doubles) {
    const char* type = doubles ? "double" : "float";
    out << "ply\n"
        << "format binary_little_endian 1.0\n"
        << kLidarloopComment << "\n"
        << "comment map of " << map.scans << " scans, voxel " << map.voxel_m << " m\n"
        << "comment colour: viridis of the scan time, purple " << map.first_time_s
        << " s to yellow " << map.last_time_s << " s\n"
        << "element vertex " << map.points.size() << "\n"
        << "property " << type << " x\n"
        << "property " << type << " y\n"
        << "property " << type << " z\n"
        << "property uchar red\n"
        << "property uchar green\n"
        << "property uchar blue\n"
        << "property double time\n"
        << "end_header\n";
}

template <typename T>
std::vector<char> VertexBytes(const core::MapCloud& map) {
    constexpr std::size_t kVertexBytes = 3 * sizeof(T) + 3 + sizeof(double);
    std::vector<char> bytes(map.points.size() * kVertexBytes);
    char* next = bytes.data();
    for (const core::MapPoint& point : map.points) {
        for (int axis = 0; axis < 3; ++axis, next += sizeof(T)) {
            detail::StoreLittle(static_cast<T>(point.position[axis]), next);
        }
        const Rgb rgb = Viridis(MapTimeFraction(map, point.time_s));
        for (const std::uint8_t channel : rgb) *next++ = static_cast<char>(channel);
        detail::StoreLittle(point.time_s, next);
        next += sizeof(double);
    }
    return bytes;
}

}  // namespace

double MapTimeFraction(const core::MapCloud& map, double time_s) {
    const double span = map.last_time_s - map.first_time_s;
    if (!(span > 0.0)) return 0.5;
    return (time_s - map.first_time_s) / span;
}

void WriteMapPly(const std::filesystem::path& file, const core::MapCloud& map) {
    const bool doubles = NeedsDoubles(map);
    std::ofstream out = detail::OpenForWriting(file, /*binary=*/true);
    WriteHeader(out, map, doubles);
    const std::vector<char> bytes = doubles ? VertexBytes<double>(map) : VertexBytes<float>(map);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) throw WriteError(file, "write failed");
}

bool IsLidarloopPly(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::string line;
    if (!std::getline(in, line) || line != "ply") return false;
    // A PLY header is a few lines; a file that is not one ends the search quickly.
    for (int k = 0; k < 64 && std::getline(in, line); ++k) {
        if (line == kLidarloopComment) return true;
        if (line == "end_header") return false;
    }
    return false;
}

}  // namespace lidarloop::io

#include "lidarloop/io/scan_reader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <string>
#include <system_error>

#include "lidarloop/io/kitti_bin.hpp"
#include "lidarloop/io/osnabrueck.hpp"
#include "lidarloop/io/pcd.hpp"
#include "lidarloop/io/ply.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/rosbag.hpp"
#include "lidarloop/io/xyz.hpp"

namespace lidarloop::io {
namespace {

using Reader = core::PointCloud (*)(const std::filesystem::path&);

struct FormatEntry {
    const char* extension;
    Reader reader;
};

constexpr FormatEntry kFormats[] = {
    {".bin", ReadKittiBin}, {".pcd", ReadPcd}, {".ply", ReadPly},         {".xyz", ReadXyz},
    {".txt", ReadXyz},      {".pts", ReadXyz}, {".3d", ReadOsnabrueck3d},
};

std::string LowerExtension(const std::filesystem::path& file) {
    std::string extension = file.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension;
}

Reader FindReader(const std::filesystem::path& file) {
    const std::string extension = LowerExtension(file);
    for (const auto& format : kFormats) {
        if (extension == format.extension) return format.reader;
    }
    return nullptr;
}

// Names of the text files beside scans that hold no points.
constexpr std::array<const char*, 3> kSidecarPrefixes = {"poses", "times", "calib"};

}  // namespace

bool IsScanFile(const std::filesystem::path& file) { return FindReader(file) != nullptr; }

bool IsSidecarFile(const std::filesystem::path& file) {
    if (file.extension() != ".txt") return false;
    const std::string stem = file.stem().string();
    return std::any_of(kSidecarPrefixes.begin(), kSidecarPrefixes.end(),
                       [&](const char* prefix) { return stem.rfind(prefix, 0) == 0; });
}

core::PointCloud ReadScan(const std::filesystem::path& file) {
    if (const auto reference = ParseBagScanReference(file.string())) return ReadBagScan(*reference);
    // Before the extension: a folder has none, and "unknown scan format ''" would hide the cause.
    std::error_code ec;
    if (std::filesystem::is_directory(file, ec)) throw ReadError(file, "is a folder, not a file");
    if (IsBagFile(file)) {
        throw ReadError(file, "is a ROS bag; name one of its scans as BAG:TOPIC:INDEX (e.g. " +
                                  file.string() +
                                  ":/points:0; `lidarloop bag-info` lists the "
                                  "topics)");
    }
    if (IsSidecarFile(file)) {
        throw ReadError(file,
                        "is named as a poses, times or calibration file (poses*, times*, "
                        "calib*.txt), not a scan");
    }
    const Reader reader = FindReader(file);
    if (reader == nullptr) {
        std::string known;
        for (const auto& format : kFormats)
            known += std::string(known.empty() ? "" : " ") + format.extension;
        throw ReadError(file, "unknown scan format " + core::Quoted(file.extension().string()) +
                                  " (known extensions: " + known + ")");
    }
    return reader(file);
}

}  // namespace lidarloop::io

#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io {

/// Layouts of a sequence of scans on disk.
enum class DatasetFormat {
    kAuto,        ///< detect from the folder's content
    kKitti,       ///< KITTI odometry: velodyne/*.bin, optional poses.txt, calib.txt, times.txt
    kFolder,      ///< a folder of .pcd/.ply/.xyz/.txt/.pts/.bin files, sorted by name
    kOsnabrueck,  ///< Osnabrück repository: scanNNN.3d with scanNNN.pose or scanNNN.frames
};

/// How to open a dataset. Empty paths mean "look in the usual place".
struct DatasetOptions {
    DatasetFormat format = DatasetFormat::kAuto;
    std::filesystem::path poses_file;  ///< KITTI poses.txt or TUM file (detected by its content)
    std::filesystem::path calib_file;  ///< KITTI calib.txt; default: calib.txt beside the scans
};

/// An ordered sequence of scans with optional ground-truth poses. Scans are loaded on demand;
/// LoadScan is thread-safe (it only reads files).
class Dataset {
public:
    Dataset(DatasetFormat format, std::filesystem::path root,
            std::vector<std::filesystem::path> scan_files, std::vector<core::StampedPose> poses);

    DatasetFormat format() const { return format_; }
    std::string FormatName() const;
    const std::filesystem::path& root() const { return root_; }
    std::size_t size() const { return scan_files_.size(); }
    const std::filesystem::path& ScanPath(std::size_t index) const;
    core::PointCloud LoadScan(std::size_t index) const;
    bool HasPoses() const { return !poses_.empty(); }
    /// One pose per scan (T_world_sensor); empty when the dataset has none.
    const std::vector<core::StampedPose>& poses() const { return poses_; }

private:
    DatasetFormat format_;
    std::filesystem::path root_;
    std::vector<std::filesystem::path> scan_files_;
    std::vector<core::StampedPose> poses_;
};

/// Opens a dataset folder, detecting its format unless `options.format` names one. Throws
/// ReadError when the path does not exist, holds no scans, the format cannot be told (the message
/// says what was looked for), or the number of poses differs from the number of scans.
Dataset OpenDataset(const std::filesystem::path& path, const DatasetOptions& options = {});

}  // namespace lidarloop::io

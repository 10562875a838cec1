#include "dataset_options.hpp"

#include "lidarloop/core/error.hpp"

namespace lidarloop::cli {

void DatasetOptions::AddTo(CLI::App& command, const std::string& format_flag, bool with_poses) {
    command
        .add_option("DATASET", path_,
                    "folder of scans (KITTI layout, scan files, Osnabrueck) or a ROS 1 bag (.bag)")
        ->required();
    command.add_option(format_flag, format_, "dataset layout: auto | kitti | folder | osnabrueck")
        ->check(CLI::IsMember({"auto", "kitti", "folder", "osnabrueck"}));
    command.add_option("--topic", topic_,
                       "a bag's sensor_msgs/PointCloud2 topic (default: its only one)");
    if (!with_poses) return;
    command.add_option("--poses", poses_, "poses file (KITTI or TUM) instead of the usual one")
        ->check(CLI::ExistingFile);
    command.add_option("--calib", calib_, "KITTI calib.txt whose Tr converts the poses")
        ->check(CLI::ExistingFile);
}

io::Dataset DatasetOptions::Open() const {
    io::DatasetOptions options;
    if (format_ == "kitti") options.format = io::DatasetFormat::kKitti;
    if (format_ == "folder") options.format = io::DatasetFormat::kFolder;
    if (format_ == "osnabrueck") options.format = io::DatasetFormat::kOsnabrueck;
    options.poses_file = poses_;
    options.calib_file = calib_;
    options.topic = topic_;
    return io::OpenDataset(path_, options);
}

}  // namespace lidarloop::cli

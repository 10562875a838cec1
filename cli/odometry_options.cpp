#include "odometry_options.hpp"

namespace lidarloop::cli {

void OdometryOptions::AddTo(CLI::App& command, const std::string& use) {
    auto* file =
        command
            .add_option(
                "--odometry", file_,
                "odometry poses, KITTI or TUM, one per scan (KITTI layout: or per frame): " + use)
            ->check(CLI::ExistingFile);
    command
        .add_option("--odometry-topic", topic_,
                    "instead of --odometry, for a bag: its nav_msgs/Odometry topic, "
                    "interpolated at the scans' stamps")
        ->excludes(file);
    command
        .add_option("--odometry-calib", calib_,
                    "KITTI calib.txt whose Tr converts --odometry's KITTI poses from KITTI's "
                    "camera frame (as --calib does for --poses)")
        ->check(CLI::ExistingFile)
        ->needs(file);
}

}  // namespace lidarloop::cli

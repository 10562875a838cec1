// libFuzzer harness: the ROS 1 bag reader (io/rosbag.hpp, through Debian's rosbag_storage) on any
// bytes: the topic list, every scan of the default PointCloud2 topic, and the odometry of the
// default nav_msgs/Odometry topic at made-up scan times. Built when lidarloop reads bags.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_input.hpp"
#include "lidarloop/io/rosbag.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace io = lidarloop::io;
    const auto file = lidarloop::fuzz::InputFile(data, size, "run.bag");
    lidarloop::fuzz::ExpectResultOrReadError(file, [&] { io::ListBagTopics(file); });
    std::vector<double> times;
    lidarloop::fuzz::ExpectResultOrReadError(file, [&] {
        const auto scans = io::BagScans::Open(file);
        for (std::size_t i = 0; i < std::min<std::size_t>(scans->size(), 8); ++i) scans->Load(i);
        times = scans->times_s();
    });
    if (times.empty()) times = {0.0, 1.0};
    lidarloop::fuzz::ExpectResultOrReadError(file, [&] { io::ReadBagOdometry(file, "", times); });
    return 0;
}

// rosbag.hpp when lidarloop is built without ROS bag support (LIDARLOOP_WITH_ROSBAG OFF, or AUTO
// without librosbag-storage-dev): every bag is an error that says how to get the support.
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/rosbag.hpp"

namespace lidarloop::io {
namespace {

[[noreturn]] void Unsupported(const std::filesystem::path& bag) {
    throw ReadError(
        bag,
        "is a ROS bag, and this lidarloop was built without ROS bag support "
        "(install librosbag-storage-dev and configure with -DLIDARLOOP_WITH_ROSBAG=ON)");
}

}  // namespace

struct BagScans::Impl {};

bool RosbagSupported() { return false; }

std::vector<BagTopic> ListBagTopics(const std::filesystem::path& bag) { Unsupported(bag); }

std::shared_ptr<const BagScans> BagScans::Open(const std::filesystem::path& bag,
                                               const std::string& /*topic*/) {
    Unsupported(bag);
}

BagScans::BagScans(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BagScans::~BagScans() = default;

const std::filesystem::path& BagScans::file() const { Unsupported({}); }
const std::string& BagScans::topic() const { Unsupported({}); }
std::size_t BagScans::size() const { return 0; }
const std::vector<double>& BagScans::times_s() const { Unsupported({}); }
core::PointCloud BagScans::Load(std::size_t /*index*/) const { Unsupported({}); }

std::vector<core::StampedPose> ReadBagOdometry(const std::filesystem::path& bag,
                                               const std::string& /*topic*/,
                                               const std::vector<double>& /*scan_times_s*/,
                                               double /*max_step_m*/) {
    Unsupported(bag);
}

}  // namespace lidarloop::io

#include "lidarloop/sim/front_end.hpp"

#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::sim {
namespace {

// More would leave about 100 points of the densest sensor's 120000: nothing a front end keeps.
constexpr std::int64_t kMaxKeepEvery = 1000;

}  // namespace

void FrontEndConfig::Validate() const {
    if (keep_every < 1 || keep_every > kMaxKeepEvery) {
        throw core::ConfigError("front_end.keep_every must be in [1, " +
                                std::to_string(kMaxKeepEvery) + "], got " +
                                std::to_string(keep_every));
    }
}

core::PointCloud KeepEvery(const core::PointCloud& cloud, std::int64_t n) {
    if (n < 1) throw core::ConfigError("keep every n-th point needs n >= 1");
    const auto step = static_cast<std::size_t>(n);
    core::PointCloud kept;
    kept.reserve(cloud.size() / step + 1);
    for (std::size_t i = 0; i < cloud.size(); i += step) kept.push_back(cloud[i]);
    return kept;
}

}  // namespace lidarloop::sim

#include "lidarloop/core/ndt/ndt_config.hpp"

#include <cmath>
#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

void Require(bool condition, const std::string& message) {
    if (!condition) throw ConfigError(message);
}

}  // namespace

void NdtConfig::Validate() const {
    CheckDeclaredRanges(kSection, *this);
    Require(FeatureCount() >= 1,
            "ndt: at least one of spherical, planar, linear classes is needed");
    Require(range_limits_m.size() <= 64, "ndt.range_limits_m holds at most 64 borders");
    for (std::size_t i = 0; i < range_limits_m.size(); ++i) {
        Require(std::isfinite(range_limits_m[i]) && range_limits_m[i] > 0.0,
                "ndt.range_limits_m must be finite and positive");
        Require(i == 0 || range_limits_m[i] > range_limits_m[i - 1],
                "ndt.range_limits_m must be strictly increasing");
    }
}

}  // namespace lidarloop::core

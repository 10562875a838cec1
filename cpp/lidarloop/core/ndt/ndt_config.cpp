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
    Require(cell_size_m >= 0.01 && cell_size_m <= 100.0, "ndt.cell_size_m must be in [0.01, 100]");
    Require(min_points_per_cell >= 3 && min_points_per_cell <= 1'000'000,
            "ndt.min_points_per_cell must be in [3, 1000000] (a shape needs 3 points)");
    Require(eigen_ratio_threshold > 0.0 && eigen_ratio_threshold < 1.0,
            "ndt.eigen_ratio_threshold (t_e) must be in (0, 1)");
    Require(spherical_classes >= 0 && spherical_classes <= 100,
            "ndt.spherical_classes must be in [0, 100]");
    Require(planar_classes >= 0 && planar_classes <= 10'000,
            "ndt.planar_classes must be in [0, 10000]");
    Require(linear_classes >= 0 && linear_classes <= 10'000,
            "ndt.linear_classes must be in [0, 10000]");
    Require(FeatureCount() >= 1,
            "ndt: at least one of spherical, planar, linear classes is needed");
    Require(range_limits_m.size() <= 64, "ndt.range_limits_m holds at most 64 borders");
    for (std::size_t i = 0; i < range_limits_m.size(); ++i) {
        Require(std::isfinite(range_limits_m[i]) && range_limits_m[i] > 0.0,
                "ndt.range_limits_m must be finite and positive");
        Require(i == 0 || range_limits_m[i] > range_limits_m[i - 1],
                "ndt.range_limits_m must be strictly increasing");
    }
    Require(ambiguity_ratio >= 0.0 && ambiguity_ratio <= 1.0,
            "ndt.ambiguity_ratio (t_a) must be in [0, 1]");
}

}  // namespace lidarloop::core

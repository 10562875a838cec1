#include "lidarloop/core/min_gap.hpp"

#include <cmath>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {

void MinGap::Validate(const std::string& field) const {
    if (!std::isfinite(value) || value < 0.0) {
        throw ConfigError(field + " must be a finite number >= 0, got " + std::to_string(value));
    }
}

std::string ToString(MinGap::Unit unit) {
    return unit == MinGap::Unit::kScans ? "scans" : "seconds";
}

MinGap::Unit ParseMinGapUnit(std::string_view name) {
    if (name == "scans") return MinGap::Unit::kScans;
    if (name == "seconds") return MinGap::Unit::kSeconds;
    throw ConfigError("unknown gap unit '" + std::string(name) + "' (valid: scans, seconds)");
}

}  // namespace lidarloop::core

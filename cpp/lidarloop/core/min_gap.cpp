#include "lidarloop/core/min_gap.hpp"

#include <array>
#include <cmath>

#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

constexpr auto kUnitNames = std::to_array<EnumName<MinGap::Unit>>({
    {MinGap::Unit::kScans, "scans"},
    {MinGap::Unit::kSeconds, "seconds"},
});
static_assert(IsOneToOne(kUnitNames));

}  // namespace

void MinGap::Validate(const std::string& field) const {
    if (!std::isfinite(value) || value < 0.0) {
        throw ConfigError(field + " must be a finite number >= 0, got " + std::to_string(value));
    }
}

std::string ToString(MinGap::Unit unit) { return std::string(NameOf(kUnitNames, unit)); }

MinGap::Unit ParseMinGapUnit(std::string_view name) {
    return ParseEnum(kUnitNames, name, "gap unit");
}

}  // namespace lidarloop::core

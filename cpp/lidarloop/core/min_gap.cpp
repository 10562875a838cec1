#include "lidarloop/core/min_gap.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"

namespace lidarloop::core {
namespace {

constexpr auto kUnitNames = std::to_array<EnumName<MinGap::Unit>>({
    {MinGap::Unit::kScans, "scans"},
    {MinGap::Unit::kSeconds, "seconds"},
    {MinGap::Unit::kMetres, "metres"},
});
static_assert(IsOneToOne(kUnitNames));

}  // namespace

void MinGap::Validate(const std::string& field) const {
    if (!std::isfinite(value) || value < 0.0) {
        throw ConfigError(field + " must be a finite number >= 0, got " + NumberText(value));
    }
}

std::string ToString(MinGap::Unit unit) { return std::string(NameOf(kUnitNames, unit)); }

MinGap::Unit ParseMinGapUnit(std::string_view name) {
    return ParseEnum(kUnitNames, name, "gap unit");
}

bool KnowsDrivePath(const std::vector<StampedPose>& poses) {
    return !poses.empty() && std::all_of(poses.begin(), poses.end(), [](const StampedPose& pose) {
        return pose.path_m.has_value();
    });
}

std::vector<double> CumulativePathM(const std::vector<StampedPose>& poses) {
    std::vector<double> path_m;
    path_m.reserve(poses.size());
    if (KnowsDrivePath(poses)) {
        for (const StampedPose& pose : poses) path_m.push_back(*pose.path_m - *poses[0].path_m);
        CheckPathM(path_m, "path length");
        return path_m;
    }
    for (std::size_t i = 0; i < poses.size(); ++i) {
        const Eigen::Vector3d position = poses[i].T_world_sensor.translation();
        if (!position.allFinite()) {
            throw Error("path length: pose " + std::to_string(i) + " has a non-finite position");
        }
        path_m.push_back(
            i == 0 ? 0.0
                   : path_m.back() + (position - poses[i - 1].T_world_sensor.translation()).norm());
    }
    return path_m;
}

void CheckPathM(std::span<const double> path_m, const std::string& what) {
    for (std::size_t i = 0; i < path_m.size(); ++i) {
        if (!std::isfinite(path_m[i])) {
            throw ConfigError(what + ": scan " + std::to_string(i) + "'s path is not finite");
        }
        if (i > 0 && path_m[i] < path_m[i - 1]) {
            throw ConfigError(what + ": scan " + std::to_string(i) + "'s path (" +
                              std::to_string(path_m[i]) + " m) lies before scan " +
                              std::to_string(i - 1) + "'s (" + std::to_string(path_m[i - 1]) +
                              " m): a path never shrinks");
        }
    }
}

}  // namespace lidarloop::core

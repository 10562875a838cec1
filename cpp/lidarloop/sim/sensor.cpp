#include "lidarloop/sim/sensor.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/sim/detail/text.hpp"

namespace lidarloop::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

void CheckRange(const char* field, double value, double lo, double hi, bool lo_open) {
    const bool ok = std::isfinite(value) && (lo_open ? value > lo : value >= lo) && value <= hi;
    if (!ok) {
        throw core::ConfigError(std::string("sensor.") + field + " must be in " +
                                (lo_open ? "(" : "[") + detail::NumberText(lo) + ", " +
                                detail::NumberText(hi) + "], got " + detail::NumberText(value));
    }
}

constexpr auto kSensorModelNames = std::to_array<core::EnumName<SensorModel>>({
    {SensorModel::kHdl64, "hdl64"},
    {SensorModel::kVlp16, "vlp16"},
    {SensorModel::kTilt180, "tilt180"},
});
static_assert(core::IsOneToOne(kSensorModelNames));

}  // namespace

std::string ToString(SensorModel model) {
    return std::string(core::NameOf(kSensorModelNames, model));
}

SensorModel ParseSensorModel(std::string_view name) {
    return core::ParseEnum(kSensorModelNames, name, "sensor");
}

void SensorConfig::Validate() const {
    CheckRange("noise_m", noise_m, 0.0, 10.0, false);
    if (!(dropout >= 0.0 && dropout < 1.0)) {
        throw core::ConfigError("sensor.dropout must be in [0, 1), got " +
                                detail::NumberText(dropout));
    }
    if (horizontal_steps && (*horizontal_steps < 1 || *horizontal_steps > 20000)) {
        throw core::ConfigError("sensor.horizontal_steps must be in [1, 20000], got " +
                                std::to_string(*horizontal_steps));
    }
    if (min_range_m) CheckRange("min_range_m", *min_range_m, 0.0, 1e4, false);
    if (max_range_m) CheckRange("max_range_m", *max_range_m, 0.0, 1e4, true);
    if (mount_height_m) CheckRange("mount_height_m", *mount_height_m, 0.0, 20.0, true);
    if (scan_period_s) CheckRange("scan_period_s", *scan_period_s, 0.0, 3600.0, true);
}

SensorSpec Resolve(const SensorConfig& config) {
    config.Validate();
    SensorSpec spec;
    spec.model = config.model;
    switch (config.model) {
        case SensorModel::kHdl64:
            spec = {config.model, 64, 1875, 0.9, 120.0, 1.73, 0.1};
            break;
        case SensorModel::kVlp16:
            spec = {config.model, 16, 1800, 0.5, 100.0, 1.73, 0.1};
            break;
        case SensorModel::kTilt180:
            spec = {config.model, 91, 361, 0.2, 30.0, 0.6, 2.0};
            break;
    }
    spec.noise_m = config.noise_m;
    spec.dropout = config.dropout;
    spec.horizontal_steps = config.horizontal_steps.value_or(spec.horizontal_steps);
    spec.min_range_m = config.min_range_m.value_or(spec.min_range_m);
    spec.max_range_m = config.max_range_m.value_or(spec.max_range_m);
    spec.mount_height_m = config.mount_height_m.value_or(spec.mount_height_m);
    spec.scan_period_s = config.scan_period_s.value_or(spec.scan_period_s);
    if (spec.min_range_m >= spec.max_range_m) {
        throw core::ConfigError("sensor.min_range_m (" + detail::NumberText(spec.min_range_m) +
                                ") must be smaller than sensor.max_range_m (" +
                                detail::NumberText(spec.max_range_m) + ")");
    }
    return spec;
}

std::vector<double> BeamElevationsDeg(SensorModel model) {
    std::vector<double> elevations;
    switch (model) {
        case SensorModel::kHdl64:
            // Two blocks of 32 lasers, the upper one about twice as dense.
            for (int i = 0; i < 32; ++i) elevations.push_back(2.0 - i * (10.33 / 31.0));
            for (int i = 0; i < 32; ++i) elevations.push_back(-8.83 - i * (15.97 / 31.0));
            break;
        case SensorModel::kVlp16:
            // Laser ids 0..15 fire in this order: -15, 1, -13, 3, ..., -1, 15 degrees.
            for (int id = 0; id < 16; ++id) {
                elevations.push_back(id % 2 == 0 ? -15.0 + id : id);
            }
            break;
        case SensorModel::kTilt180:
            for (int i = 0; i <= 90; ++i) elevations.push_back(-40.0 + i);
            break;
    }
    return elevations;
}

std::vector<Eigen::Vector3d> BeamDirections(const SensorSpec& spec) {
    const std::vector<double> elevations = BeamElevationsDeg(spec.model);
    std::vector<Eigen::Vector3d> directions;
    directions.reserve(elevations.size() * static_cast<std::size_t>(spec.horizontal_steps));
    const double steps = spec.horizontal_steps;
    if (spec.model == SensorModel::kTilt180) {
        for (const double tilt_deg : elevations) {
            const double tilt = tilt_deg * kDeg;
            for (int k = 0; k < spec.horizontal_steps; ++k) {
                // In-plane angle from +90 (left) to -90 degrees (right); one sample when 1 step.
                const double alpha = steps > 1 ? (90.0 - 180.0 * k / (steps - 1.0)) * kDeg : 0.0;
                directions.emplace_back(std::cos(alpha) * std::cos(tilt), std::sin(alpha),
                                        std::cos(alpha) * std::sin(tilt));
            }
        }
        return directions;
    }
    for (int k = 0; k < spec.horizontal_steps; ++k) {
        const double azimuth = std::numbers::pi - 2.0 * std::numbers::pi * k / steps;
        for (const double elevation_deg : elevations) {
            const double elevation = elevation_deg * kDeg;
            directions.emplace_back(std::cos(elevation) * std::cos(azimuth),
                                    std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
        }
    }
    return directions;
}

}  // namespace lidarloop::sim

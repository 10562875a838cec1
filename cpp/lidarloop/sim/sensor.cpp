
#include "lidarloop/sim/sensor.hpp"
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include "lidarloop/core/angles.hpp"
#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"

namespace lidarloop::sim {
namespace {

void CheckRange(const char* field, double value, double lo, double hi, bool lo_open) {
    const bool ok = std::isfinite(value) && (lo_open ? value > lo : value >= lo) && value <= hi;
    if (!ok) {
        throw core::ConfigError(std::string("sensor.") + field + " must be in " +
                                (lo_open ? "(" : "[") + core::NumberText(lo) + ", " +
                                core::NumberText(hi) + "], got " + core::NumberText(value));
    }
}

constexpr auto kSensorModelNames = std::to_array<core::EnumName<SensorModel>>({
    {SensorModel::kHdl64, "hdl64"},
    {SensorModel::kVlp16, "vlp16"},
    {SensorModel::kTilt180, "tilt180"},
    {SensorModel::kHdl32, "hdl32"},
    {SensorModel::kOuster64Wide, "ouster64-wide"},
    {SensorModel::kLivoxAvia, "livox-avia"},
});

// Livox-Avia-like rosette. Two wedge prisms turning in opposite directions each deflect the beam
// by the same angle, so the deflection is the sum of two equal vectors turning at these rates.
// The sum traces a rose whose petals all pass through the centre (radius
// |cos(pi (f_forward + f_backward) t)|, turning at pi (f_forward - f_backward)): about 39
// petals per scan per laser, the rose turning 171 degrees per scan. The rates are
// incommensurate (14 sqrt 2 and 6 pi), so the curve never closes: each scan goes on where the
// previous one stopped and samples new directions, as a non-repetitive scanner does.
constexpr double kPrismForwardRevPerScan = 19.798989873223331;   // 14 sqrt(2)
constexpr double kPrismBackwardRevPerScan = 18.849555921538759;  // 6 pi
constexpr double kRosetteHalfWidthDeg = 35.2;   // half of the 70.4 degree horizontal field
constexpr double kRosetteHalfHeightDeg = 38.6;  // half of the 77.2 degree vertical field
constexpr int kRosetteLasers = 6;

// HDL-32E: 32 lasers 41.34 degrees / 31 apart from -30.67 up; the even laser ids fire the lower
// 16 from the bottom up, the odd ids the upper 16 (-9.33, -8.0, ..., +10.67).
std::vector<double> Hdl32ElevationsDeg() {
    std::vector<double> elevations;
    for (int id = 0; id < 32; ++id) {
        const int from_bottom = id % 2 == 0 ? id / 2 : 16 + id / 2;
        elevations.push_back(-30.67 + from_bottom * (41.34 / 31.0));
    }
    return elevations;
}

// Ouster-like: 64 channels spread uniformly over +45 .. -45 degrees, channel 0 at the top.
std::vector<double> Ouster64WideElevationsDeg() {
    std::vector<double> elevations;
    for (int channel = 0; channel < 64; ++channel) {
        elevations.push_back(45.0 - channel * (90.0 / 63.0));
    }
    return elevations;
}

Eigen::Vector3d FromAzimuthElevation(double azimuth, double elevation) {
    return {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
            std::sin(elevation)};
}

// Every beam at each azimuth, the head turning clockwise (seen from above) from straight back.
std::vector<Eigen::Vector3d> SpinningDirections(const SensorSpec& spec) {
    const std::vector<double> elevations = BeamElevationsDeg(spec.model);
    std::vector<Eigen::Vector3d> directions;
    directions.reserve(elevations.size() * static_cast<std::size_t>(spec.horizontal_steps));
    const double steps = spec.horizontal_steps;
    for (int k = 0; k < spec.horizontal_steps; ++k) {
        const double azimuth = std::numbers::pi - 2.0 * std::numbers::pi * k / steps;
        for (const double elevation_deg : elevations) {
            directions.push_back(
                FromAzimuthElevation(azimuth, elevation_deg * core::kRadiansPerDegree));
        }
    }
    return directions;
}

// Each scan line from left to right, lines from the lowest tilt up.
std::vector<Eigen::Vector3d> TiltDirections(const SensorSpec& spec) {
    std::vector<Eigen::Vector3d> directions;
    const double steps = spec.horizontal_steps;
    for (const double tilt_deg : BeamElevationsDeg(spec.model)) {
        const double tilt = tilt_deg * core::kRadiansPerDegree;
        for (int k = 0; k < spec.horizontal_steps; ++k) {
            // In-plane angle from +90 (left) to -90 degrees (right); one sample when 1 step.
            const double alpha =
                steps > 1 ? (90.0 - 180.0 * k / (steps - 1.0)) * core::kRadiansPerDegree : 0.0;
            directions.emplace_back(std::cos(alpha) * std::cos(tilt), std::sin(alpha),
                                    std::cos(alpha) * std::sin(tilt));
        }
    }
    return directions;
}

// The 6 lasers at each sample time of scan `scan_index`; each laser's rose is the first one
// turned by 30 degrees more, so that together they fill the field evenly.
std::vector<Eigen::Vector3d> RosetteDirections(const SensorSpec& spec, std::size_t scan_index) {
    const double two_pi = 2.0 * std::numbers::pi;
    const double scan = static_cast<double>(scan_index);
    // Phases in revolutions at the start of the scan; the fractional part keeps them exact.
    const double forward_start = std::fmod(kPrismForwardRevPerScan * scan, 1.0);
    const double backward_start = std::fmod(kPrismBackwardRevPerScan * scan, 1.0);
    std::vector<Eigen::Vector3d> directions;
    directions.reserve(static_cast<std::size_t>(kRosetteLasers * spec.horizontal_steps));
    for (int k = 0; k < spec.horizontal_steps; ++k) {
        const double t = k / static_cast<double>(spec.horizontal_steps);  // in scans
        const double forward = two_pi * (forward_start + kPrismForwardRevPerScan * t);
        const double backward = two_pi * (backward_start + kPrismBackwardRevPerScan * t);
        // Unit-disc deflection: the mean of the two prisms' unit vectors.
        const Eigen::Vector2d deflection(0.5 * (std::cos(forward) + std::cos(backward)),
                                         0.5 * (std::sin(forward) - std::sin(backward)));
        for (int laser = 0; laser < kRosetteLasers; ++laser) {
            const double turn = std::numbers::pi * laser / kRosetteLasers;
            const Eigen::Vector2d d = Eigen::Rotation2Dd(turn) * deflection;
            directions.push_back(
                FromAzimuthElevation(d.x() * kRosetteHalfWidthDeg * core::kRadiansPerDegree,
                                     d.y() * kRosetteHalfHeightDeg * core::kRadiansPerDegree));
        }
    }
    return directions;
}
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
                                core::NumberText(dropout));
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
        case SensorModel::kHdl32:
            spec = {config.model, 32, 2170, 1.0, 100.0, 1.73, 0.1};
            break;
        case SensorModel::kOuster64Wide:
            spec = {config.model, 64, 1024, 0.3, 50.0, 1.73, 0.1};
            break;
        case SensorModel::kLivoxAvia:
            spec = {config.model, kRosetteLasers, 4000, 1.0, 190.0, 1.73, 0.1};
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
        throw core::ConfigError("sensor.min_range_m (" + core::NumberText(spec.min_range_m) +
                                ") must be smaller than sensor.max_range_m (" +
                                core::NumberText(spec.max_range_m) + ")");
    }
    return spec;
}

bool RepeatsEveryScan(SensorModel model) { return model != SensorModel::kLivoxAvia; }

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
        case SensorModel::kHdl32:
            elevations = Hdl32ElevationsDeg();
            break;
        case SensorModel::kOuster64Wide:
            elevations = Ouster64WideElevationsDeg();
            break;
        case SensorModel::kLivoxAvia:
            break;  // the lasers sweep a rosette
    }
    return elevations;
}

std::vector<Eigen::Vector3d> BeamDirections(const SensorSpec& spec, std::size_t scan_index) {
    switch (spec.model) {
        case SensorModel::kTilt180:
            return TiltDirections(spec);
        case SensorModel::kLivoxAvia:
            return RosetteDirections(spec, scan_index);
        case SensorModel::kHdl64:
        case SensorModel::kVlp16:
        case SensorModel::kHdl32:
        case SensorModel::kOuster64Wide:
            break;
    }
    return SpinningDirections(spec);
}

}  // namespace lidarloop::sim

#pragma once

// Degrees and radians: parameters and reports are in degrees, Eigen and <cmath> in radians.

#include <numbers>

namespace lidarloop::core {

inline constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;

}  // namespace lidarloop::core

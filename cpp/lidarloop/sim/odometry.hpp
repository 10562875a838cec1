#pragma once

#include <cstddef>
#include <cstdint>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::sim {

/// Drift of the simulated odometry: every step between consecutive scans is measured with a
/// seeded random error, and the odometry pose is the product of the measured steps from the
/// true first pose, so its error grows like a random walk (in yaw, and through yaw in position;
/// and in the step lengths). Zero noise gives the ground truth.
struct OdometryConfig {
    double yaw_noise_deg = 0.1;       ///< sigma of the yaw error of each step, degrees, [0, 10]
    double translation_noise = 0.01;  ///< sigma of the length and sideways error of each step, as
                                      ///< a fraction of its length, [0, 0.5]

    /// Throws core::ConfigError naming the first invalid field ("odometry.yaw_noise_deg ...").
    void Validate() const;
};

/// The step T_prev_next as the odometry measures it: the yaw error turns the step about the
/// previous frame's z axis, the translation error lengthens it and pushes it sideways (along the
/// previous frame's y axis). Depends only on (step, config, seed, index). Thread-safe.
core::Transform MeasureStep(const core::Transform& T_prev_next, const OdometryConfig& config,
                            std::uint64_t seed, std::size_t index);

}  // namespace lidarloop::sim

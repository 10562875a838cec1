#pragma once

#include <cstddef>
#include <cstdint>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::sim {

/// Drift of the simulated odometry: every step between consecutive scans is measured with a
/// seeded random error and a systematic one, and the odometry pose is the product of the
/// measured steps from the true first pose. The random part grows like a random walk (in yaw,
/// and through yaw in position; and in the step lengths), the systematic part like a LiDAR
/// odometry's: a scale error of the step lengths and a steady turn. The defaults (0.2 % scale,
/// 0.4 degrees per 100 m) give a KITTI RPE over 100-800 m of about 1 % on the straighter uturn
/// route (0.3-0.45 % on the compact grid route, whose segments end near where they start) and
/// 0.25-0.45 degrees per 100 m (docs/posegraph.md#simulated-drift), the order of a good LiDAR
/// odometry on KITTI. Mostly heading drift, as a LiDAR odometry's: a scale error is what loop
/// closures cannot remove. Zero noise and biases give the ground truth.
struct OdometryConfig {
    double yaw_noise_deg = 0.02;      ///< sigma of the yaw error of each step, degrees, [0, 10]
    double translation_noise = 0.01;  ///< sigma of the length and sideways error of each step, as
                                      ///< a fraction of its length, [0, 0.5]
    /// Steady turn of the odometry, degrees per 100 m travelled, [0, 100]; its sign (left or
    /// right) is drawn from the seed.
    double yaw_bias_deg_per_100m = 0.4;
    /// Scale error: every step is measured this fraction too long (negative: too short),
    /// [-0.5, 0.5].
    double length_bias = 0.002;

    /// Throws core::ConfigError naming the first invalid field ("odometry.yaw_noise_deg ...").
    void Validate() const;
};

/// The step T_prev_next as the odometry measures it: the yaw error turns the step about the
/// previous frame's z axis, the translation error lengthens it and pushes it sideways (along the
/// previous frame's y axis). Depends only on (step, config, seed, index). Thread-safe.
core::Transform MeasureStep(const core::Transform& T_prev_next, const OdometryConfig& config,
                            std::uint64_t seed, std::size_t index);

}  // namespace lidarloop::sim

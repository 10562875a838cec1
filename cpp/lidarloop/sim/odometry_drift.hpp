#pragma once

#include <string>

#include "lidarloop/core/error.hpp"
#include "lidarloop/sim/odometry.hpp"

namespace lidarloop::sim {

/// `config` with all four odometry errors (yaw noise, translation noise, yaw bias, length
/// bias) multiplied by `factor`: 0 makes the odometry the ground truth, 2 doubles its drift
/// (`lidarloop simulate --drift`, lidarloop.Simulator(drift=...)). Throws core::ConfigError for
/// a negative or NaN factor; the scaled config is validated by the simulator.
inline OdometryConfig ScaledOdometry(OdometryConfig config, double factor) {
    if (!(factor >= 0.0)) {
        throw core::ConfigError("the drift factor must be >= 0 (a factor on the default " +
                                std::string("odometry noise), got ") + std::to_string(factor));
    }
    config.yaw_noise_deg *= factor;
    config.translation_noise *= factor;
    config.yaw_bias_deg_per_100m *= factor;
    config.length_bias *= factor;
    return config;
}

}  // namespace lidarloop::sim

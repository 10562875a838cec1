#pragma once

#include <string>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/sim/odometry.hpp"

namespace lidarloop::sim {

/// `config` with all four odometry errors (yaw noise, translation noise, yaw bias, length
/// bias) multiplied by `factor`: 0 makes the odometry the ground truth, 2 doubles its drift
/// (`lidarloop simulate --drift`, lidarloop.Simulator(drift=...)). Throws core::ConfigError for
/// a negative or NaN factor, and for one that scales an error out of its range (naming both).
inline OdometryConfig ScaledOdometry(OdometryConfig config, double factor) {
    if (!(factor >= 0.0)) {
        throw core::ConfigError("the drift factor must be >= 0 (a factor on the default " +
                                std::string("odometry noise), got ") + core::NumberText(factor));
    }
    config.yaw_noise_deg *= factor;
    config.translation_noise *= factor;
    config.yaw_bias_deg_per_100m *= factor;
    config.length_bias *= factor;
    try {
        config.Validate();
    } catch (const core::ConfigError& error) {
        throw core::ConfigError("the drift factor " + core::NumberText(factor) +
                                " scales the odometry noise out of its range: " + error.what());
    }
    return config;
}

}  // namespace lidarloop::sim

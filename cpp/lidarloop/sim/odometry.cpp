
#include "lidarloop/sim/odometry.hpp"
#include <cmath>
#include <numbers>
#include <string>
#include "lidarloop/core/angles.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/sim/detail/random.hpp"

namespace lidarloop::sim {

void OdometryConfig::Validate() const {
    if (!(yaw_noise_deg >= 0.0 && yaw_noise_deg <= 10.0)) {
        throw core::ConfigError("odometry.yaw_noise_deg must be in [0, 10], got " +
                                core::NumberText(yaw_noise_deg));
    }
    if (!(translation_noise >= 0.0 && translation_noise <= 0.5)) {
        throw core::ConfigError("odometry.translation_noise must be in [0, 0.5], got " +
                                core::NumberText(translation_noise));
    }
    if (!(yaw_bias_deg_per_100m >= 0.0 && yaw_bias_deg_per_100m <= 100.0)) {
        throw core::ConfigError("odometry.yaw_bias_deg_per_100m must be in [0, 100], got " +
                                core::NumberText(yaw_bias_deg_per_100m));
    }
    if (!(length_bias >= -0.5 && length_bias <= 0.5)) {
        throw core::ConfigError("odometry.length_bias must be in [-0.5, 0.5], got " +
                                core::NumberText(length_bias));
    }
}

core::Transform MeasureStep(const core::Transform& T_prev_next, const OdometryConfig& config,
                            std::uint64_t seed, std::size_t index) {
    detail::Random rng(
        detail::StreamSeed(seed, detail::Stream::kOdometry, {static_cast<std::int64_t>(index)}));
    // The turn's direction is one draw per sequence, from a stream of its own.
    detail::Random turn(detail::StreamSeed(seed, detail::Stream::kOdometry, {-1}));
    const double turn_sign = turn.Uniform() < 0.5 ? -1.0 : 1.0;
    const Eigen::Vector3d t = T_prev_next.translation();
    const double yaw_error =
        rng.Normal() * config.yaw_noise_deg * core::kRadiansPerDegree +
        turn_sign * config.yaw_bias_deg_per_100m / 100.0 * core::kRadiansPerDegree * t.norm();
    const double length_error = rng.Normal() * config.translation_noise + config.length_bias;
    const double side_error = rng.Normal() * config.translation_noise;
    core::Transform measured = T_prev_next;
    measured.translation() =
        t * (1.0 + length_error) + Eigen::Vector3d::UnitY() * (side_error * t.norm());
    measured.prerotate(Eigen::AngleAxisd(yaw_error, Eigen::Vector3d::UnitZ()));
    return measured;
}

}  // namespace lidarloop::sim

#pragma once

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::test {

/// A pose at (x, y, z) with the given yaw, pitch and roll (radians), time `time_s`.
inline core::StampedPose MakePose(double time_s, double x, double y, double yaw_rad = 0.0,
                                  double pitch_rad = 0.0, double roll_rad = 0.0, double z = 0.0) {
    core::StampedPose pose;
    pose.time_s = time_s;
    pose.T_world_sensor = core::Transform::Identity();
    pose.T_world_sensor.translation() = Eigen::Vector3d(x, y, z);
    pose.T_world_sensor.linear() = (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
    return pose;
}

/// A vehicle driving laps of a noisy circuit (radius ~40 m) with random detours, so that
/// places are revisited in both directions; times advance by 0.1 s +- jitter (sometimes 0, so
/// equal times occur). Seeded.
inline std::vector<core::StampedPose> RandomTrajectory(unsigned seed, std::size_t count) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 1.0);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<core::StampedPose> poses;
    double t = 0.0;
    double angle = 0.0;
    double direction = 1.0;
    double detour = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
        if (unit(rng) < 0.01) direction = -direction;  // turn around
        if (unit(rng) < 0.02) detour = 30.0 * noise(rng);
        angle += direction * (0.03 + 0.01 * unit(rng));
        const double radius = 40.0 + detour + noise(rng);
        const double x = radius * std::cos(angle) + 0.5 * noise(rng);
        const double y = radius * std::sin(angle) + 0.5 * noise(rng);
        const double yaw = angle + direction * std::numbers::pi / 2 + 0.3 * noise(rng);
        const double pitch_rad = 0.05 * noise(rng);
        const double roll_rad = 0.05 * noise(rng);
        poses.push_back(MakePose(t, x, y, yaw, pitch_rad, roll_rad, 0.3 * noise(rng)));
        t += unit(rng) < 0.05 ? 0.0 : 0.1 + 0.02 * noise(rng) * 0.5;
    }
    return poses;
}

}  // namespace lidarloop::test

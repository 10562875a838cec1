#pragma once

// Synthetic trajectories with drifting odometry and loops for the pose-graph tests and the
// benchmark: all seeded, no scans.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/posegraph/pose_graph.hpp"

namespace lidarloop::test {

inline core::Transform PlanarPose(double x, double y, double yaw_rad, double z = 0.0) {
    core::Transform T = core::Transform::Identity();
    T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(x, y, z);
    return T;
}

/// `laps` laps of an ellipse (semi-axes a_m, b_m), a pose every `step_m` of arc length, heading
/// along the path, over a gentle hill (so that z, roll and pitch are not trivially zero). Odd
/// laps are driven 2 m further out, so that revisits are not exact copies.
inline std::vector<core::Transform> EllipseLaps(int laps, double a_m = 120.0, double b_m = 70.0,
                                                double step_m = 2.0) {
    std::vector<core::Transform> poses;
    double theta = 0.0;
    while (theta < 2.0 * std::numbers::pi * laps) {
        const int lap = static_cast<int>(theta / (2.0 * std::numbers::pi));
        const double lane = lap % 2 == 0 ? 0.0 : 2.0;
        const double a = a_m + lane, b = b_m + lane;
        const Eigen::Vector2d p(a * std::cos(theta), b * std::sin(theta));
        const Eigen::Vector2d dp(-a * std::sin(theta), b * std::cos(theta));
        const double z = 3.0 * std::sin(p.x() / 50.0);
        const double dz = 3.0 / 50.0 * std::cos(p.x() / 50.0) * dp.x();
        const Eigen::Vector3d forward = Eigen::Vector3d(dp.x(), dp.y(), dz).normalized();
        const Eigen::Vector3d left = Eigen::Vector3d::UnitZ().cross(forward).normalized();
        core::Transform T = core::Transform::Identity();
        T.linear().col(0) = forward;
        T.linear().col(1) = left;
        T.linear().col(2) = forward.cross(left);
        T.translation() = Eigen::Vector3d(p.x(), p.y(), z);
        poses.push_back(T);
        theta += step_m / std::hypot(dp.norm(), dz);
    }
    return poses;
}

/// Odometry of `truth`: each step with seeded random errors (translation sigma
/// translation_noise x length per axis, rotation sigma rotation_noise_deg per axis) and a
/// constant yaw bias per metre, chained from the true first pose.
inline std::vector<core::Transform> DriftingOdometry(const std::vector<core::Transform>& truth,
                                                     std::uint64_t seed,
                                                     double translation_noise = 0.01,
                                                     double rotation_noise_deg = 0.02,
                                                     double yaw_bias_deg_per_m = 0.003) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal;
    std::vector<core::Transform> odometry = {truth.front()};
    for (std::size_t i = 1; i < truth.size(); ++i) {
        core::Transform step = truth[i - 1].inverse() * truth[i];
        const double length = step.translation().norm();
        const Eigen::Vector3d t_noise{normal(rng), normal(rng), normal(rng)};
        step.translation() += translation_noise * length * t_noise;
        const Eigen::Vector3d r_noise{normal(rng), normal(rng), normal(rng)};
        const double deg = std::numbers::pi / 180.0;
        const Eigen::Vector3d rotation = rotation_noise_deg * deg * r_noise +
                                         Eigen::Vector3d(0, 0, yaw_bias_deg_per_m * deg * length);
        step.linear() =
            step.linear() *
            Eigen::AngleAxisd(rotation.norm(), rotation.normalized()).toRotationMatrix();
        odometry.push_back(odometry.back() * step);
    }
    return odometry;
}

/// True loops: for every `stride`-th scan q, the earliest scan m at least min_gap scans earlier
/// within max_distance_m, with T_match_query from the truth plus seeded noise (sigma
/// noise_m per axis, noise_deg per rotation axis).
inline std::vector<posegraph::LoopConstraint> TrueLoops(const std::vector<core::Transform>& truth,
                                                        std::uint64_t seed, std::size_t stride = 5,
                                                        std::size_t min_gap = 50,
                                                        double max_distance_m = 5.0,
                                                        double noise_m = 0.05,
                                                        double noise_deg = 0.2) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal;
    std::vector<posegraph::LoopConstraint> loops;
    for (std::size_t q = min_gap; q < truth.size(); q += stride) {
        for (std::size_t m = 0; m + min_gap <= q; ++m) {
            if ((truth[q].translation() - truth[m].translation()).norm() > max_distance_m) continue;
            posegraph::LoopConstraint loop;
            loop.query = q;
            loop.match = m;
            loop.T_match_query = truth[m].inverse() * truth[q];
            loop.T_match_query.translation() +=
                noise_m * Eigen::Vector3d{normal(rng), normal(rng), normal(rng)};
            const Eigen::Vector3d r = noise_deg * std::numbers::pi / 180.0 *
                                      Eigen::Vector3d{normal(rng), normal(rng), normal(rng)};
            loop.T_match_query.linear() =
                loop.T_match_query.linear() *
                Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix();
            loop.overlap = 0.5;
            loop.rmse_m = 0.1;
            loops.push_back(loop);
            break;
        }
    }
    return loops;
}

/// `count` wrong loops: random scan pairs at least min_gap apart with random planar transforms
/// (yaw uniform in [-180, 180) degrees, translation uniform in [-10, 10] m in x and y), the kind
/// of wrong alignment a verification could accept.
inline std::vector<posegraph::LoopConstraint> WrongLoops(std::size_t scans, std::size_t count,
                                                         std::uint64_t seed,
                                                         std::size_t min_gap = 50) {
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<std::size_t> scan(0, scans - 1);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::vector<posegraph::LoopConstraint> loops;
    while (loops.size() < count) {
        posegraph::LoopConstraint loop;
        loop.query = scan(rng);
        loop.match = scan(rng);
        if (loop.query < loop.match + min_gap) continue;
        const double x_m = 10.0 * unit(rng);
        const double y_m = 10.0 * unit(rng);
        loop.T_match_query = PlanarPose(x_m, y_m, std::numbers::pi * unit(rng));
        loop.overlap = 0.5;
        loop.rmse_m = 0.1;
        loops.push_back(loop);
    }
    return loops;
}

}  // namespace lidarloop::test

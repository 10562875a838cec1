#pragma once

#include <cmath>
#include <random>

#include <vector>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/core/voxel_grid.hpp"
#include "lidarloop/registration/verification_config.hpp"

namespace lidarloop::test {

/// The voxel centroids PrepareScan reduces `scan` to (range filter, voxels), for tests and
/// benchmarks of what it does with them.
inline std::vector<Eigen::Vector3f> VoxelCentroids(
    const core::PointCloud& scan, const registration::ScanReductionConfig& reduction = {}) {
    core::VoxelGrid voxels(reduction.voxel_m);
    for (const Eigen::Vector3f& point : scan) {
        const double range_m = point.cast<double>().norm();
        if (range_m >= reduction.min_range_m && range_m <= reduction.max_range_m)
            voxels.Add(point.cast<double>());
    }
    std::vector<Eigen::Vector3f> centroids;
    for (const core::Voxel& voxel : voxels.Voxels())
        centroids.push_back(voxel.centroid.cast<float>());
    return centroids;
}

/// The defaults, but ICP's first stage pairs every point as the later ones do: the slow path that
/// the thinned first stage replaced (IcpConfig::first_stage_structure_points).
inline registration::VerificationConfig EveryPointInEveryStage() {
    registration::VerificationConfig config;
    config.icp.first_stage_structure_points = config.icp.max_structure_points;
    config.icp.first_stage_ground_points = config.icp.max_ground_points;
    return config;
}

/// T_match_query = Translation(x, y, z) * Rz(yaw_deg).
inline core::Transform PlanarTransform(double x_m, double y_m, double yaw_deg, double z_m = 0.0) {
    core::Transform T = core::Transform::Identity();
    T.linear() =
        Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(x_m, y_m, z_m);
    return T;
}

inline core::PointCloud Transformed(const core::PointCloud& cloud, const core::Transform& T) {
    core::PointCloud out;
    out.reserve(cloud.size());
    for (const auto& p : cloud) out.push_back((T * p.cast<double>()).cast<float>());
    return out;
}

/// A synthetic, irregular place around the origin (sensor frame, z up, ground at z = -1.7 m):
/// a ground patch, building walls of differing lengths and set-backs on both sides, poles and
/// boxes, sampled every `step_m` with seeded noise. Distinct in every horizontal direction.
inline core::PointCloud SyntheticPlace(std::uint64_t seed = 1, double step_m = 0.25) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.01);
    core::PointCloud cloud;
    const auto add = [&](double x, double y, double z) {
        // One draw per statement, z first: the order of a call's arguments is the compiler's.
        const double z_noise = noise(rng);
        const double y_noise = noise(rng);
        cloud.emplace_back(static_cast<float>(x + noise(rng)), static_cast<float>(y + y_noise),
                           static_cast<float>(z + z_noise));
    };
    for (double x = -30; x <= 30; x += 2 * step_m)
        for (double y = -12; y <= 12; y += 2 * step_m) add(x, y, -1.7);
    // Walls: (x0, x1, y, height) on alternating sides.
    const double walls[][4] = {{-28, -12, 9, 8},   {-9, 4, 11, 12}, {7, 25, 8.5, 6},
                               {-25, -5, -10, 10}, {-2, 10, -8, 5}, {14, 29, -12, 9}};
    for (const auto& w : walls)
        for (double x = w[0]; x <= w[1]; x += step_m)
            for (double z = -1.7; z <= w[3] - 1.7; z += step_m) add(x, w[2], z);
    // Walls across the street ends and a side wall of a building.
    for (double y = -10; y <= 10; y += step_m)
        for (double z = -1.7; z <= 4; z += step_m) add(-30, y, z);
    for (double y = 4; y <= 11; y += step_m)
        for (double z = -1.7; z <= 6; z += step_m) add(-9, y, z);
    // Poles and boxes.
    const double poles[][2] = {{-15, 5}, {-3, -6}, {6, 6}, {18, -5}, {22, 4}};
    for (const auto& p : poles)
        for (double a = 0; a < 2 * M_PI; a += 0.5)
            for (double z = -1.7; z <= 3; z += step_m)
                add(p[0] + 0.2 * std::cos(a), p[1] + 0.2 * std::sin(a), z);
    for (double x = 2; x <= 6; x += step_m)
        for (double z = -1.7; z <= -0.2; z += step_m) {
            add(x, -4, z);
            add(x, -2.2, z);
        }
    return cloud;
}

}  // namespace lidarloop::test

#pragma once

// A Velodyne HDL-64E-like scan for benchmarks: 64 beams from +2 to -24.8 degrees, 1875 azimuth
// steps (~120k rays), cast against a ground plane, a few walls and poles. Benchmark input only;
// the project's simulator (issue 6) is the realistic one.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::bench {

inline core::PointCloud SyntheticHdl64Scan(unsigned seed) {
    constexpr int kBeams = 64;
    constexpr int kAzimuthSteps = 1875;
    constexpr double kSensorHeight_m = 1.73;
    constexpr double kMaxRange_m = 120.0;
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.02);
    // Walls as planes n.x = d (vertical normals), poles as vertical cylinders (x, y, radius).
    const double wall_angles[] = {0.1, 1.7, 3.3, 4.6};
    const double wall_distances[] = {12.0, 8.0, 20.0, 15.0};
    const double poles[][3] = {{5, 3, 0.2}, {-4, 6, 0.3}, {9, -7, 0.25}, {-10, -3, 0.4}};
    core::PointCloud cloud;
    cloud.reserve(kBeams * kAzimuthSteps);
    for (int beam = 0; beam < kBeams; ++beam) {
        const double elevation = (2.0 - 26.8 * beam / (kBeams - 1)) * M_PI / 180.0;
        for (int step = 0; step < kAzimuthSteps; ++step) {
            const double azimuth = 2.0 * M_PI * step / kAzimuthSteps;
            const double dx = std::cos(elevation) * std::cos(azimuth);
            const double dy = std::cos(elevation) * std::sin(azimuth);
            const double dz = std::sin(elevation);
            double t = kMaxRange_m;
            if (dz < 0.0) t = std::min(t, kSensorHeight_m / -dz);
            for (int w = 0; w < 4; ++w) {
                const double along = dx * std::cos(wall_angles[w]) + dy * std::sin(wall_angles[w]);
                if (along > 1e-9) {
                    const double hit = wall_distances[w] / along;
                    if (dz * hit < 6.0 - kSensorHeight_m) t = std::min(t, hit);
                }
            }
            for (const auto& pole : poles) {
                const double horizontal = std::hypot(dx, dy);
                const double along = (pole[0] * dx + pole[1] * dy) / horizontal;
                const double miss = std::abs(pole[0] * dy - pole[1] * dx) / horizontal;
                if (along > 0.0 && miss < pole[2]) {
                    t = std::min(t,
                                 (along - std::sqrt(pole[2] * pole[2] - miss * miss)) / horizontal);
                }
            }
            if (t >= kMaxRange_m) continue;  // no return
            const double range = t + noise(rng);
            cloud.push_back(Eigen::Vector3d(dx * range, dy * range, dz * range).cast<float>());
        }
    }
    return cloud;
}

}  // namespace lidarloop::bench

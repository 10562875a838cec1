#pragma once

// Plain reference implementations of the NDT cells, for oracle tests of the fast paths.

#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <tuple>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/core/ndt/ndt_cells.hpp"
#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::core::test_reference {

using CellIndex = std::tuple<long, long, long>;

/// Every point into each of the 8 cells [i h, i h + q), h = q / 2, that contain it, by
/// definition (Magnusson II-A).
inline std::map<CellIndex, std::vector<Eigen::Vector3d>> BruteForceCellPoints(
    const PointCloud& cloud, double q) {
    std::map<CellIndex, std::vector<Eigen::Vector3d>> cells;
    const double h = q / 2.0;
    for (const auto& pf : cloud) {
        const Eigen::Vector3d p = pf.cast<double>();
        const long x = static_cast<long>(std::floor(p.x() * (1.0 / h)));
        const long y = static_cast<long>(std::floor(p.y() * (1.0 / h)));
        const long z = static_cast<long>(std::floor(p.z() * (1.0 / h)));
        for (long dx = 0; dx < 2; ++dx)
            for (long dy = 0; dy < 2; ++dy)
                for (long dz = 0; dz < 2; ++dz) cells[{x - dx, y - dy, z - dz}].push_back(p);
    }
    return cells;
}

/// The cells with at least `min_points` points: two-pass mean and unbiased covariance.
inline std::vector<NdtCell> BruteForceCells(const PointCloud& cloud, double q, int min_points) {
    std::vector<NdtCell> cells;
    for (const auto& [index, points] : BruteForceCellPoints(cloud, q)) {
        if (static_cast<int>(points.size()) < min_points) continue;
        NdtCell cell;
        const auto n = static_cast<double>(points.size());
        cell.point_count = static_cast<int>(points.size());
        for (const auto& p : points) cell.mean_m += p / n;
        for (const auto& p : points) {
            cell.covariance_m2 += (p - cell.mean_m) * (p - cell.mean_m).transpose() / (n - 1.0);
        }
        cells.push_back(cell);
    }
    return cells;
}

// A street-like scan around a sensor at the origin: ground, walls at several yaws, a tilted
// roof, poles and bushes, with 1 cm noise; about 40k points, denser near the sensor.
class StreetScan {
public:
    explicit StreetScan(unsigned seed) : rng_(seed) {}

    PointCloud Build() {
        for (int i = 0; i < 14000; ++i) {  // ground 1.8 m below the sensor, r in [2, 30] m
            const double r = Uniform(2.0, 30.0);
            const double a = Uniform(0.0, 2.0 * std::numbers::pi);
            Add({r * std::cos(a), r * std::sin(a), -1.8});
        }
        Wall({8.0, 0.0, 0.0}, 0.0, 9000);   // facing the sensor along x
        Wall({0.0, -6.0, 0.0}, 1.4, 7000);  // about 80 degrees of yaw
        Wall({-9.0, 9.0, 0.0}, 2.3, 5000);  // an oblique facade
        Plane({-4.0, -12.0, 3.0}, Eigen::Vector3d(0.3, 0.2, 0.93).normalized(), 3000);
        for (int pole = 0; pole < 6; ++pole) Pole({Uniform(-15, 15), Uniform(-15, 15), 0}, 300);
        for (int bush = 0; bush < 5; ++bush) Bush({Uniform(-12, 12), Uniform(-12, 12), -1.3}, 400);
        return cloud_;
    }

private:
    double Uniform(double low, double high) {
        return std::uniform_real_distribution<double>(low, high)(rng_);
    }
    void Add(const Eigen::Vector3d& p) {
        std::normal_distribution<double> noise(0.0, 0.01);
        cloud_.push_back(
            (p + Eigen::Vector3d{noise(rng_), noise(rng_), noise(rng_)}).cast<float>());
    }
    // A vertical wall through `centre`, 20 m long and 6 m high, turned by `yaw_rad` about z.
    void Wall(const Eigen::Vector3d& centre, double yaw_rad, int points) {
        const Eigen::Vector3d along(-std::sin(yaw_rad), std::cos(yaw_rad), 0.0);
        for (int i = 0; i < points; ++i) {
            Add(centre + Uniform(-10.0, 10.0) * along + Eigen::Vector3d(0, 0, Uniform(-1.8, 4.2)));
        }
    }
    void Plane(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, int points) {
        const Eigen::Vector3d a = normal.unitOrthogonal();
        const Eigen::Vector3d b = normal.cross(a);
        for (int i = 0; i < points; ++i) Add(centre + Uniform(-4, 4) * a + Uniform(-4, 4) * b);
    }
    void Pole(const Eigen::Vector3d& base, int points) {
        for (int i = 0; i < points; ++i) Add(base + Eigen::Vector3d(0, 0, Uniform(-1.8, 3.0)));
    }
    void Bush(const Eigen::Vector3d& centre, int points) {
        std::normal_distribution<double> spread(0.0, 0.4);
        for (int i = 0; i < points; ++i) {
            Add(centre + Eigen::Vector3d{spread(rng_), spread(rng_), spread(rng_)});
        }
    }

    std::mt19937 rng_;
    PointCloud cloud_;
};

}  // namespace lidarloop::core::test_reference

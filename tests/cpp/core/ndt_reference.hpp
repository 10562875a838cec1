#pragma once

// Plain reference implementations of the NDT cells, for oracle tests of the fast paths.

#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/core/ndt_cells.hpp"
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

}  // namespace lidarloop::core::test_reference

#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::core {

/// One cell of the normal distributions transform: the mean and covariance of the points inside
/// a cube of side q (Magnusson et al. 2009, section II-A).
struct NdtCell {
    Eigen::Vector3d mean_m = Eigen::Vector3d::Zero();         ///< sensor frame, metres
    Eigen::Matrix3d covariance_m2 = Eigen::Matrix3d::Zero();  ///< unbiased (n-1), square metres
    int point_count = 0;
};

/// Bookkeeping of a cell computation.
struct NdtCellStats {
    std::size_t points_used = 0;  ///< finite points binned into the grid
    /// Non-finite points, and points farther than min(100 km, 2^20 half-cells) from the sensor
    /// on some axis (beyond any LiDAR's reach; the grid index would overflow).
    std::size_t points_skipped = 0;
    std::size_t sparse_cells = 0;  ///< occupied cells with fewer than the minimum point count
};

/// The cells of ComputeNdtCells as columns (structure of arrays), the layout the descriptor's
/// vectorised passes read: entry i of every column belongs to cell i. Covariances are unbiased
/// (n-1) like NdtCell's; only their upper triangle is stored.
struct NdtCellColumns {
    std::vector<double> mean_x_m, mean_y_m, mean_z_m;
    std::vector<double> cov_xx_m2, cov_xy_m2, cov_xz_m2, cov_yy_m2, cov_yz_m2, cov_zz_m2;
    std::vector<int> point_count;

    std::size_t size() const { return point_count.size(); }
    void clear();
    NdtCell Cell(std::size_t i) const;
};

/// Computes the overlapping NDT grid of Magnusson II-A: cubic cells of side `cell_size_m` whose
/// corners lie on a lattice of spacing cell_size_m / 2, so every point falls into 8 cells. Cells
/// with fewer than `min_points` points are dropped (their covariance says nothing about shape).
///
/// Implementation: points are sorted by half-size voxel (LSD radix sort of their voxel keys) and
/// summed into voxel moments; each cell is the sum of the moments of its 2x2x2 voxels, formed by
/// three separable passes over the sorted voxel list. Output order is deterministic (sorted by
/// cell index). Throws ConfigError for a cell size outside [0.01, 100] m or min_points < 2.
/// O(n) in the number of points.
std::vector<NdtCell> ComputeNdtCells(const PointCloud& cloud, double cell_size_m, int min_points,
                                     NdtCellStats* stats = nullptr);

/// ComputeNdtCells into columns: the same cells in the same order. `cells` is cleared first and
/// its capacity reused, so a caller describing many scans allocates once.
void ComputeNdtCellColumns(const PointCloud& cloud, double cell_size_m, int min_points,
                           NdtCellColumns& cells, NdtCellStats* stats = nullptr);

}  // namespace lidarloop::core

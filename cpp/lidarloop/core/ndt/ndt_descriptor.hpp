#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/core/ndt/ndt_cells.hpp"
#include "lidarloop/core/ndt/ndt_config.hpp"
#include "lidarloop/core/ndt/ndt_shape.hpp"
#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::core {

/// Range rows of a descriptor are compared this many at a time (one vector of floats).
inline constexpr int kNdtRowBlock = 8;

/// One appearance descriptor F (eq. 3): rows = range intervals, columns = the feature vector f
/// of eq. (1) (s spherical, p planar, l linear classes), entries = cell counts. Fill it with
/// SetNdtCounts, which keeps counts, total and normalised consistent.
struct NdtDescriptor {
    int rows = 0;
    int cols = 0;
    std::vector<float> counts;  ///< row-major rows x cols
    /// counts / total, what eq. (8) compares, stored column by column with the rows padded with
    /// zeros to PaddedRows(): entry (row, col) is at col * PaddedRows() + row. A comparison then
    /// takes kNdtRowBlock range rows per vector.
    std::vector<float> normalised;
    double total = 0.0;  ///< ||F||_1, number of classified cells
    Eigen::Matrix3d R_aligned_sensor = Eigen::Matrix3d::Identity();  ///< rotation R_y R_z used

    int PaddedRows() const { return (rows + kNdtRowBlock - 1) / kNdtRowBlock * kNdtRowBlock; }
};

/// Sets the counts of `f` (row-major rows x cols), its total ||F||_1 and its normalised form.
/// Throws ConfigError when rows or cols is not positive, the count of entries is not rows x cols,
/// or a count is negative or not finite.
void SetNdtCounts(NdtDescriptor& f, int rows, int cols, std::vector<float> counts);

/// The descriptors of one scan, one per rotation candidate (section II-C).
struct NdtDescriptorSet {
    std::vector<NdtDescriptor> descriptors;
    NdtCellStats cell_stats;
    std::size_t degenerate_cells = 0;
};

/// Builds the descriptor set of `cloud`. Throws EmptyInputError when no cell is counted, with a
/// message saying why: no cell had enough points, all cells were degenerate, or the classes of
/// the classified cells are disabled (s, p or l = 0). ConfigError for an invalid config.
/// Thread-safe.
NdtDescriptorSet ComputeNdtDescriptorSet(const PointCloud& cloud, const NdtConfig& config);

/// sigma of eq. (8): sum over range intervals of the Euclidean distance between the rows of the
/// 1-norm-normalised descriptors, times max(|F|,|G|)/min(|F|,|G|). Symmetric, 0 for equal input
/// (two empty descriptors included), infinity when exactly one is empty. The descriptors must
/// have the same shape (ConfigError otherwise).
double NdtDifference(const NdtDescriptor& f, const NdtDescriptor& g);

/// sigma' of eq. (9): the smallest sigma over all pairs of the two sets.
double NdtSetDifference(const NdtDescriptorSet& f, const NdtDescriptorSet& g);

}  // namespace lidarloop::core

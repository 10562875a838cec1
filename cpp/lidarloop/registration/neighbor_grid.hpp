#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace lidarloop::registration {

/// Exact neighbour searches for points of bounded density, such as one scan's voxel centroids or
/// its prepared surfaces: a 2-D grid of x-y columns in which the points of each grid row lie
/// contiguously, so a query reads a few short ranges instead of walking a tree, and nothing is
/// built but one counting sort. It finds what PointTree finds (Knn: the k nearest, nearest first,
/// equal distances by index; NearestWithin: the nearest within a bound). Holds a copy of the
/// points, which must be finite. Queries are const and thread-safe, each thread with its own
/// Scratch.
class NeighborGrid {
public:
    /// A query's working memory, and the radius that served the last query: queries near each
    /// other need about the same (so ask in SpatialOrder when all points are queried).
    struct Scratch {
        // Candidates within the radius: squared distances (metres²) and the points' indices,
        // which break ties.
        std::vector<float> distance_m2;
        std::vector<std::uint32_t> index;
        std::vector<std::uint32_t> ranked;  // positions in those, nearest first
        std::vector<std::uint64_t> keys;    // many candidates: distance bits over index, sorted
        float radius_m = 0.0F;
    };

    /// `cell_m`: the columns' edge, metres, about the points' spacing (finite, > 0; widened when
    /// the points spread over more than a few columns per point, so memory stays linear).
    NeighborGrid(const std::vector<Eigen::Vector3f>& points, float cell_m);

    /// The indices of the `k` nearest points to `query` (fewer when there are fewer points),
    /// nearest first.
    void Knn(const Eigen::Vector3f& query, int k, Scratch& scratch,
             std::vector<std::uint32_t>& indices) const;

    /// The index of the point nearest to `query` when it is closer than `max_distance_m`, else
    /// -1: what PointTree::Nearest finds. `hint` (an index, or -1) is a point likely to be near,
    /// such as ICP's partner of the previous iteration: only points closer than it are looked
    /// for, so a good hint leaves a column or two to read; it is returned when nothing is closer.
    std::int64_t NearestWithin(const Eigen::Vector3f& query, float max_distance_m,
                               std::int64_t hint = -1) const;

    /// Heap bytes held: the points' copy, their order and the column offsets.
    std::size_t MemoryBytes() const;

    /// The points' indices column by column: asked in this order, each query starts from about
    /// the radius it needs (the last one's), where a scan's own order jumps between near and far.
    const std::vector<std::uint32_t>& SpatialOrder() const { return original_; }
    float cell_m() const { return cell_m_; }

private:
    struct Span {
        std::int64_t first = 0, last = 0;  // columns, inclusive; empty when first > last
    };
    std::uint32_t RowBegin(std::int64_t row, const Span& x) const {
        return column_start_[static_cast<std::size_t>(row * columns_x_ + x.first)];
    }
    std::uint32_t RowEnd(std::int64_t row, const Span& x) const {
        return column_start_[static_cast<std::size_t>(row * columns_x_ + x.last + 1)];
    }
    // The columns within `radius_m` of `centre` (an x or y coordinate), perhaps one more at
    // either end: reading a column too many costs time, never a neighbour.
    Span ColumnsWithin(float centre, float radius_m, float origin, std::int64_t count) const;
    // The points within `radius_m` of `query` (all points, when the columns within it are the
    // whole grid) into scratch.distance_m2 and scratch.index, in column order; returns whether
    // the whole grid was read.
    bool Collect(const Eigen::Vector3f& query, float radius_m, Scratch& scratch) const;
    // The `wanted` nearest of the collected points, nearest first (equal distances by index),
    // or all of them when there are fewer; returns the squared distance of the last.
    static float Nearest(std::size_t wanted, Scratch& scratch, std::vector<std::uint32_t>& indices);

    float cell_m_ = 1.0F;
    double inverse_cell_ = 1.0;
    float min_x_ = 0.0F, min_y_ = 0.0F;
    std::int64_t columns_x_ = 0, columns_y_ = 0;
    std::vector<Eigen::Vector3f> points_;  // in column order (row by row)
    std::vector<std::uint32_t> original_;  // points_[i] is the constructor's points[original_[i]]
    std::vector<std::uint32_t> slot_of_;   // the inverse: points[i] is points_[slot_of_[i]]
    std::vector<std::uint32_t> column_start_;  // columns_x_ * columns_y_ + 1 offsets into points_
};

}  // namespace lidarloop::registration

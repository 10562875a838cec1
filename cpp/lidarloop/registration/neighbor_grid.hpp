#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace lidarloop::registration {

/// An exact k-nearest-neighbour search for points of bounded density, such as one scan's voxel
/// centroids: a 2-D grid of x-y columns in which the points of each grid row lie contiguously,
/// so a query reads a few short ranges instead of walking a tree, and nothing is built but one
/// counting sort. It finds what PointTree finds (the k nearest, nearest first, equal distances by
/// index; the nearest within a bound). Holds a copy of the points, which must be finite. Queries
/// are const and thread-safe (Knn: each thread with its own Scratch).
class NeighborGrid {
public:
    /// A query's working memory, and the radius that served the last query: queries near each
    /// other need about the same (PrepareScan asks in scan order).
    struct Scratch {
        std::vector<std::pair<float, std::uint32_t>> candidates;  // squared metres, index
        float radius_m = 0.0F;
    };

    /// `cell_m`: the columns' edge, metres, about the points' spacing (finite, > 0; widened when
    /// the points spread over more than a few columns per point, so memory stays linear).
    NeighborGrid(const std::vector<Eigen::Vector3f>& points, float cell_m);

    /// Index of the point nearest to `query` when closer than `max_distance_m`, else -1. Given
    /// `hint` (an index, or -1) that is likely near, only points closer than it are looked for,
    /// and the hint is returned when none is: PointTree::Nearest's contract (ICP passes the last
    /// iteration's partner).
    std::int64_t Nearest(const Eigen::Vector3f& query, float max_distance_m,
                         std::int64_t hint = -1) const;

    /// The indices of the `k` nearest points to `query` (fewer when there are fewer points),
    /// nearest first.
    void Knn(const Eigen::Vector3f& query, int k, Scratch& scratch,
             std::vector<std::uint32_t>& indices) const;

    /// The points' indices column by column: asked in this order, each query starts from about
    /// the radius it needs (the last one's), where a scan's own order jumps between near and far.
    const std::vector<std::uint32_t>& SpatialOrder() const { return original_; }
    float cell_m() const { return cell_m_; }

private:
    struct Span {
        std::int64_t first = 0, last = 0;  // columns, inclusive; empty when first > last
    };
    // Rows are searched from the query's outwards while they may hold a point within the bound.
    float RowGap(std::int64_t row, float y) const;
    Span ColumnsWithin(float low, float high, float origin, std::int64_t count) const;
    // Adds the points of the columns within `radius_m` of `query` (in x and y) that lie within
    // it, or all of them when those columns are the whole grid; returns whether they were.
    bool Collect(const Eigen::Vector3f& query, float radius_m,
                 std::vector<std::pair<float, std::uint32_t>>& candidates) const;

    float cell_m_ = 1.0F;
    float min_x_ = 0.0F, min_y_ = 0.0F;
    std::int64_t columns_x_ = 0, columns_y_ = 0;
    std::vector<Eigen::Vector3f> points_;      // in column order (row by row)
    std::vector<std::uint32_t> original_;      // points_[i] is (*points)[original_[i]]
    std::vector<std::uint32_t> slot_;          // the inverse: (*points)[i] is points_[slot_[i]]
    std::vector<std::uint32_t> column_start_;  // columns_x_ * columns_y_ + 1 offsets into points_
};

}  // namespace lidarloop::registration

#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace lidarloop::core {

/// One occupied voxel of a VoxelGrid: the mean of its points and of the values they carried.
struct Voxel {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< metres, the points' frame
    double mean_value = 0.0;                             ///< e.g. the mean scan time, seconds
    std::uint64_t count = 0;                             ///< points averaged
};

/// Points averaged into cubic voxels of edge voxel_m (voxel (i, j, k) holds the points with
/// floor(p / voxel_m) = (i, j, k)), fed a point at a time from any number of clouds: memory is
/// linear in the occupied voxels, not in the points. Each point carries a value (a scan time)
/// that is averaged with it. Voxels come out in the order of their first point, so the result is
/// deterministic for a given input order. An open-addressing table of voxel indices; not
/// thread-safe for writing.
class VoxelGrid {
public:
    /// Throws core::ConfigError unless `voxel_m` is finite and > 0.
    explicit VoxelGrid(double voxel_m);

    /// Adds `point` (metres) with `value`. A non-finite point, or one more than 1e15 voxels from
    /// the origin, is skipped: returns false.
    bool Add(const Eigen::Vector3d& point, double value = 0.0);
    /// Adds `points` with `value` as Add does, returning how many were added. Faster for large
    /// grids: the table lookups of a batch of points are prefetched together, where one at a
    /// time each would wait for memory (a map's table does not fit in the cache).
    std::size_t AddAll(std::span<const Eigen::Vector3d> points, double value = 0.0);
    /// Room for `voxels` voxels without growing the table.
    void Reserve(std::size_t voxels);

    /// Doubles the edge: each 2x2x2 block of voxels becomes one, with the same centroid, mean
    /// value, count and order as if every point had been added at the new edge (cells nest:
    /// floor(floor(x / v) / 2) = floor(x / 2v), also in floating point), up to rounding of the
    /// sums. How a map keeps to a size bound without holding its points.
    void Coarsen();

    double voxel_m() const { return voxel_m_; }
    std::size_t size() const { return entries_.size(); }
    bool empty() const { return entries_.empty(); }
    /// The occupied voxels in the order of their first point.
    std::vector<Voxel> Voxels() const;
    /// Heap bytes held (voxels and table).
    std::size_t MemoryBytes() const;

private:
    struct Cell {
        std::int64_t x = 0, y = 0, z = 0;
        bool operator==(const Cell&) const = default;
    };
    // A voxel's cell and sums side by side: a hit touches one cache line (64 bytes).
    struct Entry {
        Cell cell;
        Eigen::Vector3d point = Eigen::Vector3d::Zero();
        double value = 0.0;
        std::uint64_t count = 0;
    };

    // Its cell, or false when the point cannot be placed (non-finite, too far).
    bool CellOf(const Eigen::Vector3d& point, Cell& cell) const;
    std::size_t BucketOf(const Cell& cell) const;
    Entry& EntryOf(const Cell& cell);  // inserts an empty voxel when new
    void Rehash(std::size_t buckets);

    double voxel_m_;
    std::vector<Entry> entries_;        // in the order of their first point
    std::vector<std::uint32_t> table_;  // entry index + 1; 0 = empty; size a power of two
    // The voxel of the last point: consecutive points of a scan often share it.
    Cell last_cell_;
    std::size_t last_entry_ = 0;
};

}  // namespace lidarloop::core

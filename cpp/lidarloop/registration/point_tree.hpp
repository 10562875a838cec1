#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace lidarloop::registration {

/// A static k-d tree over float points (metres): nanoflann's, behind a pimpl. Registration
/// searches with NeighborGrid, which finds the same neighbours faster on a scan's points; this
/// tree is the library reference it is tested and benchmarked against. core::KdTree3 is the
/// double-precision tree for evaluation. Queries are const and thread-safe.
class PointTree {
public:
    /// Refers to `points`, which must outlive the tree and stay unchanged. Points must be finite.
    explicit PointTree(const std::vector<Eigen::Vector3f>* points);
    ~PointTree();
    PointTree(PointTree&&) noexcept;
    PointTree& operator=(PointTree&&) noexcept;
    PointTree(const PointTree&) = delete;
    PointTree& operator=(const PointTree&) = delete;

    /// Index of the point nearest to `query` when it is closer than `max_distance_m`, else -1.
    std::int64_t Nearest(const Eigen::Vector3f& query, float max_distance_m) const;
    /// The same, given a point `hint` (an index, or -1) likely to be near: the search only looks
    /// for points closer than the hint, which prunes most of the tree when the hint is good (the
    /// previous correspondence of an ICP iteration). Returns the hint when nothing is closer.
    std::int64_t Nearest(const Eigen::Vector3f& query, float max_distance_m,
                         std::int64_t hint) const;
    /// The indices of the `k` nearest points (fewer when the tree is smaller), nearest first.
    void Knn(const Eigen::Vector3f& query, int k, std::vector<std::uint32_t>& indices) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace lidarloop::registration

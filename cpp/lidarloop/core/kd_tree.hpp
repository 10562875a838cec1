#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace lidarloop::core {

/// One neighbour found by KdTree3: the index of the point and its Euclidean distance in metres.
struct Neighbor {
    std::size_t index = 0;
    double distance_m = 0.0;
};

/// A static k-d tree over 3-D points (metres, any common frame), for exact radius and nearest
/// neighbour queries. nanoflann does the work behind a pimpl; its types never appear here.
///
/// Every answer is decided by the same exact predicate, the squared Euclidean distance computed
/// as `(p - q).squaredNorm()` in double, so a brute-force loop with that expression gives
/// identical results (nanoflann's own rounding only steers the search, with a safety margin).
/// Ties in distance go to the smaller index; a non-finite query finds nothing. Queries are const
/// and thread-safe; building is O(n log n), a query O(log n + k) on well-spread data.
class KdTree3 {
public:
    /// Builds the tree over `points`. Throws core::Error when a point is not finite.
    explicit KdTree3(std::vector<Eigen::Vector3d> points);
    ~KdTree3();
    KdTree3(KdTree3&&) noexcept;
    KdTree3& operator=(KdTree3&&) noexcept;
    KdTree3(const KdTree3&) = delete;
    KdTree3& operator=(const KdTree3&) = delete;

    std::size_t size() const;
    /// The points, in the order given to the constructor (indices refer to this order).
    const std::vector<Eigen::Vector3d>& points() const;

    /// Indices of all points strictly closer than `radius_m` to `query`
    /// (`(p - query).squaredNorm() < radius_m * radius_m`), sorted ascending. `radius_m` must be
    /// >= 0 and not NaN (+inf returns every point); throws core::Error otherwise.
    std::vector<std::size_t> RadiusSearch(const Eigen::Vector3d& query, double radius_m) const;

    /// The point nearest to `query`; nullopt for an empty tree.
    std::optional<Neighbor> Nearest(const Eigen::Vector3d& query) const;

    /// The point nearest to `query` among those for which `accept(index)` is true; nullopt when
    /// no point is accepted. Exact; when `accept` rejects most points near the query the search
    /// visits more of the tree (worst case O(n)).
    std::optional<Neighbor> NearestIf(const Eigen::Vector3d& query,
                                      const std::function<bool(std::size_t)>& accept) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace lidarloop::core

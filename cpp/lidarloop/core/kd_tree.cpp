#include "lidarloop/core/kd_tree.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <nanoflann.hpp>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

// nanoflann's dataset interface over our point vector.
struct PointsAdaptor {
    const std::vector<Eigen::Vector3d>* points = nullptr;

    std::size_t kdtree_get_point_count() const { return points->size(); }
    double kdtree_get_pt(std::size_t index, std::size_t dim) const {
        return (*points)[index][static_cast<Eigen::Index>(dim)];
    }
    template <class BoundingBox>
    bool kdtree_get_bbox(BoundingBox& /*unused*/) const {
        return false;
    }
};

using Metric = nanoflann::L2_Simple_Adaptor<double, PointsAdaptor, double, std::size_t>;
using Index = nanoflann::KDTreeSingleIndexAdaptor<Metric, PointsAdaptor, 3, std::size_t>;

// nanoflann sums the squared differences in its own order and prunes with incrementally updated
// bounds; widening the bound it sees by this margin guarantees that every point passing our exact
// predicate reaches the result set, where the exact predicate decides.
double Widen(double squared_m2) {
    return squared_m2 * (1.0 + 1e-9) + std::numeric_limits<double>::min();
}

// Collects the indices passing the exact radius predicate.
class RadiusCollector {
public:
    using DistanceType = double;
    using IndexType = std::size_t;

    RadiusCollector(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& query,
                    double radius_m, std::vector<std::size_t>& out)
        : points_(points),
          query_(query),
          squared_radius_(radius_m * radius_m),
          bound_(Widen(squared_radius_)),
          out_(out) {}

    bool full() const { return true; }
    double worstDist() const { return bound_; }
    bool addPoint(double /*approximate*/, std::size_t index) {
        if ((points_[index] - query_).squaredNorm() < squared_radius_) out_.push_back(index);
        return true;
    }

private:
    const std::vector<Eigen::Vector3d>& points_;
    const Eigen::Vector3d& query_;
    double squared_radius_;
    double bound_;
    std::vector<std::size_t>& out_;
};

// Keeps the nearest accepted point; the bound shrinks as better points are found.
class NearestAccepted {
public:
    using DistanceType = double;
    using IndexType = std::size_t;

    NearestAccepted(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& query,
                    const std::function<bool(std::size_t)>* accept)
        : points_(points), query_(query), accept_(accept) {}

    bool full() const { return true; }
    double worstDist() const { return bound_; }
    bool addPoint(double /*approximate*/, std::size_t index) {
        if (accept_ != nullptr && !(*accept_)(index)) return true;
        const double squared = (points_[index] - query_).squaredNorm();
        if (!found_ || squared < best_squared_ || (squared == best_squared_ && index < best_)) {
            found_ = true;
            best_ = index;
            best_squared_ = squared;
            bound_ = Widen(squared);
        }
        return true;
    }
    std::optional<Neighbor> Result() const {
        if (!found_) return std::nullopt;
        return Neighbor{best_, std::sqrt(best_squared_)};
    }

private:
    const std::vector<Eigen::Vector3d>& points_;
    const Eigen::Vector3d& query_;
    const std::function<bool(std::size_t)>* accept_;
    bool found_ = false;
    std::size_t best_ = 0;
    double best_squared_ = 0.0;
    double bound_ = std::numeric_limits<double>::infinity();
};

}  // namespace

struct KdTree3::Impl {
    explicit Impl(std::vector<Eigen::Vector3d> input)
        : points(std::move(input)),
          adaptor{&points},
          index(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {}

    std::vector<Eigen::Vector3d> points;
    PointsAdaptor adaptor;
    Index index;
};

namespace {

std::vector<Eigen::Vector3d> CheckedPoints(std::vector<Eigen::Vector3d> points) {
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (!points[i].allFinite()) {
            throw Error("KdTree3: point " + std::to_string(i) + " is not finite");
        }
    }
    return points;
}

}  // namespace

KdTree3::KdTree3(std::vector<Eigen::Vector3d> points)
    : impl_(std::make_unique<Impl>(CheckedPoints(std::move(points)))) {}

KdTree3::~KdTree3() = default;
KdTree3::KdTree3(KdTree3&&) noexcept = default;
KdTree3& KdTree3::operator=(KdTree3&&) noexcept = default;

std::size_t KdTree3::size() const { return impl_->points.size(); }

const std::vector<Eigen::Vector3d>& KdTree3::points() const { return impl_->points; }

std::vector<std::size_t> KdTree3::RadiusSearch(const Eigen::Vector3d& query,
                                               double radius_m) const {
    if (std::isnan(radius_m) || radius_m < 0.0) {
        throw Error("KdTree3::RadiusSearch: radius_m must be >= 0, got " +
                    std::to_string(radius_m));
    }
    std::vector<std::size_t> found;
    if (impl_->points.empty() || !query.allFinite()) return found;
    RadiusCollector collector(impl_->points, query, radius_m, found);
    impl_->index.findNeighbors(collector, query.data(), nanoflann::SearchParams(32, 0.0f, false));
    std::sort(found.begin(), found.end());
    return found;
}

std::optional<Neighbor> KdTree3::Nearest(const Eigen::Vector3d& query) const {
    return NearestIf(query, nullptr);
}

std::optional<Neighbor> KdTree3::NearestIf(const Eigen::Vector3d& query,
                                           const std::function<bool(std::size_t)>& accept) const {
    if (impl_->points.empty() || !query.allFinite()) return std::nullopt;
    NearestAccepted result(impl_->points, query, accept ? &accept : nullptr);
    impl_->index.findNeighbors(result, query.data(), nanoflann::SearchParams());
    return result.Result();
}

}  // namespace lidarloop::core

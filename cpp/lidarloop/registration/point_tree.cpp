#include "lidarloop/registration/point_tree.hpp"

#include <nanoflann.hpp>

namespace lidarloop::registration {
namespace {

struct PointsAdaptor {
    const std::vector<Eigen::Vector3f>* points = nullptr;

    std::size_t kdtree_get_point_count() const { return points->size(); }
    float kdtree_get_pt(std::size_t index, std::size_t dim) const {
        return (*points)[index][static_cast<Eigen::Index>(dim)];
    }
    template <class BoundingBox>
    bool kdtree_get_bbox(BoundingBox& /*unused*/) const {
        return false;
    }
};

using Metric = nanoflann::L2_Simple_Adaptor<float, PointsAdaptor, float, std::uint32_t>;
using Index = nanoflann::KDTreeSingleIndexAdaptor<Metric, PointsAdaptor, 3, std::uint32_t>;

// The nearest point closer than a bound; the bound prunes the search from the start, which makes
// queries with no neighbour in range (most points of a wrong alignment) cheap.
class NearestWithin {
public:
    using DistanceType = float;
    using IndexType = std::uint32_t;

    explicit NearestWithin(float max_squared_m2, std::int64_t start_index = -1)
        : best_squared_m2_(max_squared_m2), best_index_(start_index) {}

    bool full() const { return true; }
    float worstDist() const { return best_squared_m2_; }
    bool addPoint(float squared_m2, std::uint32_t index) {
        if (squared_m2 < best_squared_m2_) {
            best_squared_m2_ = squared_m2;
            best_index_ = index;
        }
        return true;
    }
    std::int64_t best_index() const { return best_index_; }

private:
    float best_squared_m2_;
    std::int64_t best_index_;
};

}  // namespace

struct PointTree::Impl {
    explicit Impl(const std::vector<Eigen::Vector3f>* points)
        : adaptor{points}, index(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(12)) {
        index.buildIndex();
    }
    PointsAdaptor adaptor;
    Index index;
};

PointTree::PointTree(const std::vector<Eigen::Vector3f>* points)
    : impl_(std::make_unique<Impl>(points)) {}
PointTree::~PointTree() = default;
PointTree::PointTree(PointTree&&) noexcept = default;
PointTree& PointTree::operator=(PointTree&&) noexcept = default;

std::int64_t PointTree::Nearest(const Eigen::Vector3f& query, float max_distance_m) const {
    return Nearest(query, max_distance_m, -1);
}

std::int64_t PointTree::Nearest(const Eigen::Vector3f& query, float max_distance_m,
                                std::int64_t hint) const {
    const std::vector<Eigen::Vector3f>& points = *impl_->adaptor.points;
    if (points.empty()) return -1;
    float bound_m2 = max_distance_m * max_distance_m;
    std::int64_t start = -1;
    if (hint >= 0 && static_cast<std::size_t>(hint) < points.size()) {
        const float hint_m2 = (points[static_cast<std::size_t>(hint)] - query).squaredNorm();
        if (hint_m2 < bound_m2) bound_m2 = hint_m2, start = hint;
    }
    NearestWithin result(bound_m2, start);
    impl_->index.findNeighbors(result, query.data(), nanoflann::SearchParams(10));
    return result.best_index();
}

void PointTree::Knn(const Eigen::Vector3f& query, int k,
                    std::vector<std::uint32_t>& indices) const {
    indices.resize(static_cast<std::size_t>(k));
    thread_local std::vector<float> squared_m2;  // no allocation per query
    squared_m2.resize(indices.size());
    const std::size_t found =
        impl_->index.knnSearch(query.data(), indices.size(), indices.data(), squared_m2.data());
    indices.resize(found);
}

}  // namespace lidarloop::registration

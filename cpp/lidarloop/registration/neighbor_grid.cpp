#include "lidarloop/registration/neighbor_grid.hpp"

#include <algorithm>
#include <cmath>

namespace lidarloop::registration {
namespace {

// Columns at most per point (and at least this many in all): a sparse or far-flung cloud gets
// wider columns instead of a grid of mostly empty ones.
constexpr double kColumnsPerPoint = 4.0;
constexpr double kMinColumns = 4096.0;
// A query's columns reach this little beyond its radius, so rounding in the column arithmetic
// can never leave out a point within the radius.
constexpr double kReachMargin = 1e-5;
// The next query starts from the last one's k-th distance times this: near enough to succeed
// at once most of the time, small enough not to read many extra points.
constexpr float kRadiusCarry = 1.2F;

std::int64_t ColumnOf(double coordinate, double origin, double cell_m, std::int64_t count) {
    const double column = std::floor((coordinate - origin) / cell_m);
    // Clamped before the cast: a far query must not overflow it.
    return static_cast<std::int64_t>(std::clamp(column, -1.0, static_cast<double>(count)));
}

}  // namespace

NeighborGrid::NeighborGrid(const std::vector<Eigen::Vector3f>& cloud, float cell_m) {
    cell_m_ = std::isfinite(cell_m) && cell_m > 0.0F ? cell_m : 1.0F;
    if (cloud.empty()) return;
    Eigen::Vector3f low = cloud.front(), high = cloud.front();
    for (const auto& point : cloud) {
        low = low.cwiseMin(point);
        high = high.cwiseMax(point);
    }
    min_x_ = low.x();
    min_y_ = low.y();
    const double limit =
        std::max(kMinColumns, kColumnsPerPoint * static_cast<double>(cloud.size()));
    for (;;) {
        // The arithmetic of ColumnOf, so the farthest point falls in the last column.
        const double x = std::floor((static_cast<double>(high.x()) - min_x_) / cell_m_) + 1.0;
        const double y = std::floor((static_cast<double>(high.y()) - min_y_) / cell_m_) + 1.0;
        if (x * y <= limit) {
            columns_x_ = static_cast<std::int64_t>(x);
            columns_y_ = static_cast<std::int64_t>(y);
            break;
        }
        cell_m_ = static_cast<float>(cell_m_ * std::max(1.01, std::sqrt(x * y / limit)));
    }

    // A counting sort by column, rows one after another: a row's columns are one range.
    const auto columns = static_cast<std::size_t>(columns_x_ * columns_y_);
    std::vector<std::uint32_t> column_of(cloud.size());
    column_start_.assign(columns + 1, 0);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const Eigen::Vector3f& point = cloud[i];
        const auto x = ColumnOf(point.x(), min_x_, cell_m_, columns_x_);
        const auto y = ColumnOf(point.y(), min_y_, cell_m_, columns_y_);
        column_of[i] = static_cast<std::uint32_t>(y * columns_x_ + x);
        ++column_start_[column_of[i] + 1];
    }
    for (std::size_t c = 0; c < columns; ++c) column_start_[c + 1] += column_start_[c];
    points_.resize(cloud.size());
    original_.resize(cloud.size());
    slot_.resize(cloud.size());
    std::vector<std::uint32_t> next(column_start_.begin(), column_start_.end() - 1);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const std::uint32_t slot = next[column_of[i]]++;
        points_[slot] = cloud[i];
        original_[slot] = static_cast<std::uint32_t>(i);
        slot_[i] = slot;
    }
}

NeighborGrid::Span NeighborGrid::ColumnsWithin(float low, float high, float origin,
                                               std::int64_t count) const {
    const double reach = static_cast<double>(high - low) * kReachMargin + kReachMargin;
    return {std::max<std::int64_t>(0, ColumnOf(low - reach, origin, cell_m_, count)),
            std::min<std::int64_t>(count - 1, ColumnOf(high + reach, origin, cell_m_, count))};
}

float NeighborGrid::RowGap(std::int64_t row, float y) const {
    const double low = min_y_ + static_cast<double>(row) * cell_m_;
    const double gap = std::max({0.0, low - y, y - (low + cell_m_)});
    // Shrunk a little: rounding must not skip a row that holds a point within the bound.
    return static_cast<float>(gap * (1.0 - kReachMargin) - kReachMargin);
}

std::int64_t NeighborGrid::Nearest(const Eigen::Vector3f& query, float max_distance_m,
                                   std::int64_t hint) const {
    if (points_.empty() || !query.allFinite() || !(max_distance_m > 0.0F)) return -1;
    float bound_m2 = max_distance_m * max_distance_m;
    std::int64_t best = -1;
    if (hint >= 0 && static_cast<std::size_t>(hint) < points_.size()) {
        const Eigen::Vector3f& at = points_[slot_[static_cast<std::size_t>(hint)]];
        const float dx = at.x() - query.x(), dy = at.y() - query.y(), dz = at.z() - query.z();
        const float hint_m2 = dx * dx + dy * dy + dz * dz;
        if (hint_m2 < bound_m2) bound_m2 = hint_m2, best = hint;
    }
    std::int64_t best_slot = -1;
    const std::int64_t centre = std::clamp<std::int64_t>(
        ColumnOf(query.y(), min_y_, cell_m_, columns_y_), 0, columns_y_ - 1);
    const auto search_row = [&](std::int64_t row) {
        if (row < 0 || row >= columns_y_) return false;
        const float gap_m = RowGap(row, query.y());
        if (gap_m > 0.0F && gap_m * gap_m >= bound_m2) return false;
        const float reach_m = std::sqrt(bound_m2);
        const Span x = ColumnsWithin(query.x() - reach_m, query.x() + reach_m, min_x_, columns_x_);
        if (x.first > x.last) return true;
        const std::uint32_t end =
            column_start_[static_cast<std::size_t>(row * columns_x_ + x.last + 1)];
        for (std::uint32_t i = column_start_[static_cast<std::size_t>(row * columns_x_ + x.first)];
             i < end; ++i) {
            const float dx = points_[i].x() - query.x();
            const float dy = points_[i].y() - query.y();
            const float dz = points_[i].z() - query.z();
            const float squared_m2 = dx * dx + dy * dy + dz * dz;
            if (squared_m2 < bound_m2) bound_m2 = squared_m2, best_slot = i;
        }
        return true;
    };
    // Outwards from the query's row; each side ends at its first row beyond the bound.
    bool below = true, above = true;
    search_row(centre);
    for (std::int64_t step = 1; below || above; ++step) {
        if (below) below = search_row(centre - step);
        if (above) above = search_row(centre + step);
    }
    return best_slot >= 0 ? original_[static_cast<std::size_t>(best_slot)] : best;
}

bool NeighborGrid::Collect(const Eigen::Vector3f& query, float radius_m,
                           std::vector<std::pair<float, std::uint32_t>>& candidates) const {
    const Span x = ColumnsWithin(query.x() - radius_m, query.x() + radius_m, min_x_, columns_x_);
    const Span y = ColumnsWithin(query.y() - radius_m, query.y() + radius_m, min_y_, columns_y_);
    const bool whole_grid =
        x.first == 0 && x.last == columns_x_ - 1 && y.first == 0 && y.last == columns_y_ - 1;
    if (x.first > x.last) return whole_grid;
    const float radius_m2 = radius_m * radius_m;
    for (std::int64_t row = y.first; row <= y.last; ++row) {
        const std::uint32_t begin =
            column_start_[static_cast<std::size_t>(row * columns_x_ + x.first)];
        const std::uint32_t end =
            column_start_[static_cast<std::size_t>(row * columns_x_ + x.last + 1)];
        for (std::uint32_t i = begin; i < end; ++i) {
            // Summed as nanoflann sums (x, y, z in turn), so distances and their order agree.
            const float dx = points_[i].x() - query.x();
            const float dy = points_[i].y() - query.y();
            const float dz = points_[i].z() - query.z();
            const float squared_m2 = dx * dx + dy * dy + dz * dz;
            if (squared_m2 <= radius_m2 || whole_grid)
                candidates.emplace_back(squared_m2, original_[i]);
        }
    }
    return whole_grid;
}

void NeighborGrid::Knn(const Eigen::Vector3f& query, int k, Scratch& scratch,
                       std::vector<std::uint32_t>& indices) const {
    indices.clear();
    if (k <= 0 || points_.empty() || !query.allFinite()) return;
    const std::size_t wanted = std::min(static_cast<std::size_t>(k), points_.size());
    auto& candidates = scratch.candidates;
    float radius_m = scratch.radius_m > 0.0F ? scratch.radius_m : cell_m_;
    for (;;) {
        candidates.clear();
        // Every point outside the columns read is farther than the radius: once `wanted` lie
        // within it, they include the nearest.
        if (Collect(query, radius_m, candidates) || candidates.size() >= wanted) break;
        radius_m *= 2.0F;
    }
    const auto kept = candidates.begin() + static_cast<std::ptrdiff_t>(wanted);
    std::nth_element(candidates.begin(), kept - 1, candidates.end());
    std::sort(candidates.begin(), kept);
    indices.reserve(wanted);
    for (auto it = candidates.begin(); it != kept; ++it) indices.push_back(it->second);
    scratch.radius_m =
        std::max(kRadiusCarry * std::sqrt(candidates[wanted - 1].first), 0.5F * cell_m_);
}

}  // namespace lidarloop::registration

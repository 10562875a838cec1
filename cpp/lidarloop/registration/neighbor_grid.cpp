#include "lidarloop/registration/neighbor_grid.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

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
// at once most of the time, small enough not to read many extra points; a query that finds too
// few widens its radius by kRadiusGrowth until it has them. Each candidate costs its share of a
// ranking quadratic in their number, so small steps pay: 1.1 and 1.3 instead of 1.2 and 2 made
// PrepareScan 5 % (HDL-64E) and 11 % (VLP-16) faster (docs/BENCHMARK.md).
constexpr float kRadiusCarry = 1.1F;
constexpr float kRadiusGrowth = 1.3F;
// Up to this many candidates are ordered by counting ranks (quadratic, but vectorised and without
// branches to mispredict: faster than a selection and a sort for the 15-50 of a neighbourhood).
constexpr std::size_t kRankedAtMost = 64;

// Summed as nanoflann sums (x, y, z in turn), so distances and their order agree with
// PointTree's.
float SquaredDistance(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
    const float dx = a.x() - b.x();
    const float dy = a.y() - b.y();
    const float dz = a.z() - b.z();
    return dx * dx + dy * dy + dz * dz;
}

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
    inverse_cell_ = 1.0 / static_cast<double>(cell_m_);
    for (std::size_t c = 0; c < columns; ++c) column_start_[c + 1] += column_start_[c];
    points_.resize(cloud.size());
    original_.resize(cloud.size());
    std::vector<std::uint32_t> next(column_start_.begin(), column_start_.end() - 1);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const std::uint32_t slot = next[column_of[i]]++;
        points_[slot] = cloud[i];
        original_[slot] = static_cast<std::uint32_t>(i);
    }
    slot_of_.resize(cloud.size());
    for (std::size_t slot = 0; slot < original_.size(); ++slot)
        slot_of_[original_[slot]] = static_cast<std::uint32_t>(slot);
}

NeighborGrid::Span NeighborGrid::ColumnsWithin(float centre, float radius_m, float origin,
                                               std::int64_t count) const {
    // Without floor (a library call on baseline x86-64) and division: the columns where the
    // constructor's ColumnOf puts points within the radius, perhaps one more at either end.
    const auto column = [&](double at) -> std::int64_t {
        const double t = (at - static_cast<double>(origin)) * inverse_cell_;
        if (!(t >= 0.0)) return -1;
        return t >= static_cast<double>(count) ? count : static_cast<std::int64_t>(t);
    };
    const double reach = static_cast<double>(radius_m) * (1.0 + kReachMargin) + kReachMargin;
    return {std::max<std::int64_t>(0, column(static_cast<double>(centre) - reach)),
            std::min<std::int64_t>(count - 1, column(static_cast<double>(centre) + reach))};
}

bool NeighborGrid::Collect(const Eigen::Vector3f& query, float radius_m, Scratch& scratch) const {
    auto& distance_m2 = scratch.distance_m2;
    auto& index = scratch.index;
    distance_m2.clear();
    index.clear();
    const Span x = ColumnsWithin(query.x(), radius_m, min_x_, columns_x_);
    const Span y = ColumnsWithin(query.y(), radius_m, min_y_, columns_y_);
    const bool whole_grid =
        x.first == 0 && x.last == columns_x_ - 1 && y.first == 0 && y.last == columns_y_ - 1;
    if (x.first > x.last) return whole_grid;
    const float bound_m2 =
        whole_grid ? std::numeric_limits<float>::infinity() : radius_m * radius_m;
    std::size_t readable = 0;
    for (std::int64_t row = y.first; row <= y.last; ++row)
        readable += RowEnd(row, x) - RowBegin(row, x);
    distance_m2.resize(readable);
    index.resize(readable);
    std::size_t found = 0;
    for (std::int64_t row = y.first; row <= y.last; ++row) {
        for (std::uint32_t i = RowBegin(row, x), end = RowEnd(row, x); i < end; ++i) {
            const float squared_m2 = SquaredDistance(points_[i], query);
            // Written always, kept when within: no branch to mispredict.
            distance_m2[found] = squared_m2;
            index[found] = original_[i];
            found += squared_m2 <= bound_m2 ? 1 : 0;
        }
    }
    distance_m2.resize(found);
    index.resize(found);
    return whole_grid;
}

namespace {

// The `kept` nearest of the candidates, nearest first (equal distances by index), by counting
// for each the ones before it: quadratic, but vectorised and without a branch per comparison.
// Distances are almost never equal, so the ranks first count strictly nearer candidates alone
// (one comparison a pair); only when two are equal, which shows as ranks summing to less than
// 0 + 1 + ... + (found - 1), are they counted again with the index breaking ties.
void RankByCounting(const std::vector<float>& distance_m2, const std::vector<std::uint32_t>& index,
                    std::size_t kept, std::vector<std::uint32_t>& ranked) {
    const std::size_t found = distance_m2.size();
    ranked.resize(found);
    std::size_t rank_sum = 0;
    for (std::size_t i = 0; i < found; ++i) {
        const float d = distance_m2[i];
        std::uint32_t before = 0;
        for (std::size_t j = 0; j < found; ++j)
            before += static_cast<std::uint32_t>(distance_m2[j] < d);
        ranked[before] = static_cast<std::uint32_t>(i);
        rank_sum += before;
    }
    if (rank_sum != found * (found - 1) / 2) {
        for (std::size_t i = 0; i < found; ++i) {
            const float d = distance_m2[i];
            const std::uint32_t id = index[i];
            std::uint32_t before = 0;
            for (std::size_t j = 0; j < found; ++j) {
                before += static_cast<std::uint32_t>(distance_m2[j] < d) |
                          (static_cast<std::uint32_t>(distance_m2[j] == d) &
                           static_cast<std::uint32_t>(index[j] < id));
            }
            ranked[before] = static_cast<std::uint32_t>(i);
        }
    }
    ranked.resize(kept);
}

}  // namespace

float NeighborGrid::Nearest(std::size_t wanted, Scratch& scratch,
                            std::vector<std::uint32_t>& indices) {
    const auto& distance_m2 = scratch.distance_m2;
    const auto& index = scratch.index;
    const std::size_t found = distance_m2.size();
    const std::size_t kept = std::min(found, wanted);
    indices.resize(kept);
    if (found <= kRankedAtMost) {
        RankByCounting(distance_m2, index, kept, scratch.ranked);
        for (std::size_t r = 0; r < kept; ++r) indices[r] = index[scratch.ranked[r]];
        return kept == 0 ? 0.0F : distance_m2[scratch.ranked[kept - 1]];
    }
    // Many candidates: a squared distance's bits (>= 0, so ordered as the floats are) over the
    // point's index, which breaks ties.
    auto& keys = scratch.keys;
    keys.resize(found);
    for (std::size_t i = 0; i < found; ++i)
        keys[i] = std::uint64_t{std::bit_cast<std::uint32_t>(distance_m2[i])} << 32 | index[i];
    const auto last = keys.begin() + static_cast<std::ptrdiff_t>(kept);
    std::nth_element(keys.begin(), last - 1, keys.end());
    std::sort(keys.begin(), last);
    for (std::size_t r = 0; r < kept; ++r) indices[r] = static_cast<std::uint32_t>(keys[r]);
    return std::bit_cast<float>(static_cast<std::uint32_t>(keys[kept - 1] >> 32));
}

std::int64_t NeighborGrid::NearestWithin(const Eigen::Vector3f& query, float max_distance_m,
                                         std::int64_t hint) const {
    if (points_.empty() || !query.allFinite() || !(max_distance_m > 0.0F)) return -1;
    float bound_m2 = max_distance_m * max_distance_m;
    std::int64_t best_slot = -1;
    if (hint >= 0 && static_cast<std::uint64_t>(hint) < slot_of_.size()) {
        const std::uint32_t slot = slot_of_[static_cast<std::size_t>(hint)];
        const float hint_m2 = SquaredDistance(points_[slot], query);
        if (hint_m2 < bound_m2) bound_m2 = hint_m2, best_slot = slot;
    }
    // Rows outward from the query's while a row's edge is nearer than the bound found so far,
    // the columns narrowed to that bound: the nearer the first points found, the less is read.
    float spans_bound_m2 = bound_m2;
    Span x = ColumnsWithin(query.x(), std::sqrt(bound_m2), min_x_, columns_x_);
    const Span y = ColumnsWithin(query.y(), std::sqrt(bound_m2), min_y_, columns_y_);
    if (x.first <= x.last && y.first <= y.last) {
        // The query in row units; a row's edge `gap` rows away is gap * cell_m_ from it, less a
        // margin for rounding (reading a row too many costs time, never a point).
        const double row_at = (static_cast<double>(query.y()) - min_y_) * inverse_cell_;
        const std::int64_t centre =
            std::clamp(static_cast<std::int64_t>(std::max(row_at, 0.0)), y.first, y.last);
        const auto reachable = [&](double gap_rows) {
            const double gap_m = std::max(0.0, gap_rows * cell_m_ - kReachMargin);
            return gap_m * gap_m <= static_cast<double>(bound_m2);
        };
        for (std::int64_t step = 0;; ++step) {
            if (bound_m2 < spans_bound_m2) {
                spans_bound_m2 = bound_m2;
                x = ColumnsWithin(query.x(), std::sqrt(bound_m2), min_x_, columns_x_);
            }
            const std::int64_t low = centre - step, high = centre + step;
            const bool below = low >= y.first && reachable(row_at - static_cast<double>(low + 1));
            const bool above =
                step > 0 && high <= y.last && reachable(static_cast<double>(high) - row_at);
            if (!below && !above) break;
            for (const std::int64_t row : {below ? low : -1, above ? high : -1}) {
                if (row < 0) continue;
                for (std::uint32_t i = RowBegin(row, x), end = RowEnd(row, x); i < end; ++i) {
                    const float squared_m2 = SquaredDistance(points_[i], query);
                    if (squared_m2 < bound_m2) bound_m2 = squared_m2, best_slot = i;
                }
            }
        }
    }
    return best_slot < 0 ? -1 : std::int64_t{original_[static_cast<std::size_t>(best_slot)]};
}

std::size_t NeighborGrid::MemoryBytes() const {
    return points_.capacity() * sizeof(Eigen::Vector3f) +
           (original_.capacity() + slot_of_.capacity() + column_start_.capacity()) *
               sizeof(std::uint32_t);
}

void NeighborGrid::Knn(const Eigen::Vector3f& query, int k, Scratch& scratch,
                       std::vector<std::uint32_t>& indices) const {
    indices.clear();
    if (k <= 0 || points_.empty() || !query.allFinite()) return;
    const std::size_t wanted = std::min(static_cast<std::size_t>(k), points_.size());
    float radius_m = scratch.radius_m > 0.0F ? scratch.radius_m : cell_m_;
    // Every point outside the columns read is farther than the radius: once `wanted` lie within
    // it, they are the nearest.
    while (!Collect(query, radius_m, scratch) && scratch.distance_m2.size() < wanted)
        radius_m *= kRadiusGrowth;
    const float kth_m2 = Nearest(wanted, scratch, indices);
    scratch.radius_m = std::max(kRadiusCarry * std::sqrt(kth_m2), 0.5F * cell_m_);
}

}  // namespace lidarloop::registration

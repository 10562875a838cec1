#include "lidarloop/core/ndt/ndt_cells.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

constexpr double kMaxCoordinate_m = 100'000.0;
// Voxel indices stay within +-2^20 so that three axes of 21 bits fit one 64-bit key.
constexpr double kMaxVoxelIndex = static_cast<double>((1 << 20) - 4);

// Count, first and (upper-triangle) second raw moments of the points of a voxel or cell, in
// sensor coordinates. The covariance then loses digits to cancellation with distance from the
// sensor (measured: errors of 5e-9 m^2 at 1 km, 3e-7 m^2 at 10 km): negligible within a
// LiDAR's range, where a 1 cm thick plane has variances of 1e-4 m^2; see MeanAndCovariance for
// cells whose points coincide.
struct Moments {
    std::array<double, 10> m{};  // n, sx, sy, sz, sxx, sxy, sxz, syy, syz, szz

    void Add(const Eigen::Vector3d& p) {
        const double values[10] = {1.0,           p.x(),         p.y(),         p.z(),
                                   p.x() * p.x(), p.x() * p.y(), p.x() * p.z(), p.y() * p.y(),
                                   p.y() * p.z(), p.z() * p.z()};
        for (int i = 0; i < 10; ++i) m[i] += values[i];
    }
    Moments& operator+=(const Moments& other) {
        for (int i = 0; i < 10; ++i) m[i] += other.m[i];
        return *this;
    }
};

struct KeyedMoments {
    std::uint64_t key;
    Moments moments;
};

// Packs voxel indices (z, y, x from high to low bits, each shifted to start at 1) into one key,
// so that sorting keys sorts by (z, y, x) and a shift by one voxel along an axis is a constant
// step. The margin of 1 lets the box sums step one voxel below the lowest without borrowing.
struct KeyLayout {
    Eigen::Array3i min_index;
    int bits[3];
    std::uint64_t step[3];
    int total_bits;

    static int BitsFor(int span) {
        int bits = 1;
        while ((1 << bits) <= span) ++bits;
        return bits;
    }
    KeyLayout(const Eigen::Array3i& lo, const Eigen::Array3i& hi) : min_index(lo) {
        total_bits = 0;
        for (int axis = 0; axis < 3; ++axis) {
            bits[axis] = BitsFor(hi[axis] - lo[axis] + 2);
            step[axis] = std::uint64_t{1} << total_bits;
            total_bits += bits[axis];
        }
    }
    std::uint64_t Key(const Eigen::Array3i& index) const {
        std::uint64_t key = 0;
        for (int axis = 0; axis < 3; ++axis) {
            key += static_cast<std::uint64_t>(index[axis] - min_index[axis] + 1) * step[axis];
        }
        return key;
    }
};

bool IsUsable(const Eigen::Vector3f& p, float max_coordinate_m) {
    return std::abs(p.x()) <= max_coordinate_m && std::abs(p.y()) <= max_coordinate_m &&
           std::abs(p.z()) <= max_coordinate_m;  // false for NaN, too
}

int FloorToInt(double value) {
    const auto truncated = static_cast<int>(value);
    return truncated - (value < static_cast<double>(truncated) ? 1 : 0);
}

// Sorts `items` stably by key_of(item) < 2^key_bits: least significant digit first, all digit
// histograms counted in one pass, digits of at most 14 bits (an HDL-64E scan's keys have about 27
// bits: two passes; 14 rather than 11 bits measured 5 % faster on the whole descriptor), and a
// pass skipped when every item has the same digit. Stable, so the points of a voxel keep the
// scanner's order and their sums do not depend on the sort.
template <typename Item, typename KeyOf>
void RadixSort(std::vector<Item>& items, int key_bits, std::vector<Item>& scratch,
               std::vector<std::uint32_t>& counts, KeyOf key_of) {
    constexpr int kMaxDigitBits = 14;
    if (items.size() < 2 || key_bits <= 0) return;
    const int passes = (key_bits + kMaxDigitBits - 1) / kMaxDigitBits;
    const int digit_bits = (key_bits + passes - 1) / passes;
    const std::size_t buckets = std::size_t{1} << digit_bits;
    const std::uint64_t digit_mask = buckets - 1;
    counts.assign(static_cast<std::size_t>(passes) * buckets, 0);
    for (const Item& item : items) {
        const std::uint64_t key = key_of(item);
        for (int pass = 0; pass < passes; ++pass) {
            ++counts[pass * buckets + ((key >> (pass * digit_bits)) & digit_mask)];
        }
    }
    scratch.resize(items.size());
    for (int pass = 0; pass < passes; ++pass) {
        const int shift = pass * digit_bits;
        std::uint32_t* start = counts.data() + pass * buckets;
        if (start[(key_of(items.front()) >> shift) & digit_mask] == items.size()) continue;
        std::uint32_t offset = 0;
        for (std::size_t b = 0; b < buckets; ++b) offset += std::exchange(start[b], offset);
        for (const Item& item : items)
            scratch[start[(key_of(item) >> shift) & digit_mask]++] = item;
        items.swap(scratch);
    }
}

// How a (voxel key, point index) pair is stored for the sort: one 64-bit word with the key above
// the index when both fit (every real scan; half the memory traffic), else a pair.
struct PackedItems {
    int index_bits;
    std::uint64_t Make(std::uint64_t key, std::uint32_t index) const {
        return (key << index_bits) | index;
    }
    std::uint64_t Key(std::uint64_t item) const { return item >> index_bits; }
    std::uint32_t Index(std::uint64_t item) const {
        return static_cast<std::uint32_t>(item & ((std::uint64_t{1} << index_bits) - 1));
    }
};

struct PairItems {
    using Item = std::pair<std::uint64_t, std::uint32_t>;
    Item Make(std::uint64_t key, std::uint32_t index) const { return {key, index}; }
    std::uint64_t Key(const Item& item) const { return item.first; }
    std::uint32_t Index(const Item& item) const { return item.second; }
};

int BitsFor(std::size_t count) {
    int bits = 1;
    while (bits < 64 && (std::uint64_t{1} << bits) < count) ++bits;
    return bits;
}

// Scratch memory reused by later calls on the same thread: a scan's grid needs a few MB, and
// fresh allocations of that size cost more in page faults than the arithmetic on them.
struct Workspace {
    std::vector<std::uint64_t> packed;
    std::vector<std::uint64_t> packed_scratch;
    std::vector<PairItems::Item> pairs;
    std::vector<PairItems::Item> pairs_scratch;
    std::vector<std::uint32_t> digit_counts;
    std::vector<KeyedMoments> blocks;
    std::vector<KeyedMoments> scratch;
};

Workspace& ThreadWorkspace() {
    thread_local Workspace workspace;
    return workspace;
}

// The voxel index bounds of the usable points, which fix the key layout. Bounds of the
// coordinates suffice: floor(x / h) is monotonic in x.
bool VoxelBounds(const PointCloud& cloud, double inverse_voxel_size, float max_coordinate_m,
                 NdtCellStats& stats, Eigen::Array3i& lo, Eigen::Array3i& hi) {
    Eigen::Array3f min_m = Eigen::Array3f::Constant(std::numeric_limits<float>::infinity());
    Eigen::Array3f max_m = -min_m;
    for (const Eigen::Vector3f& p : cloud) {
        if (!IsUsable(p, max_coordinate_m)) {
            ++stats.points_skipped;
            continue;
        }
        min_m = min_m.min(p.array());
        max_m = max_m.max(p.array());
    }
    stats.points_used = cloud.size() - stats.points_skipped;
    if (stats.points_used == 0) return false;
    for (int axis = 0; axis < 3; ++axis) {
        lo[axis] = FloorToInt(min_m[axis] * inverse_voxel_size);
        hi[axis] = FloorToInt(max_m[axis] * inverse_voxel_size);
    }
    return true;
}

// Sorts the usable points by voxel key and sums the moments of each run of equal keys into
// ws.blocks. Sorting does not depend on the order in which the scanner wrote its points (ring by
// ring or column by column), unlike a hash table whose lookups miss when consecutive points
// change voxel.
template <typename Codec, typename Item>
void SortAndSumVoxels(const PointCloud& cloud, double inverse_voxel_size, float max_coordinate_m,
                      const KeyLayout& layout, std::size_t points_used, const Codec& codec,
                      std::vector<Item>& items, std::vector<Item>& scratch, Workspace& ws) {
    // Every point gets an item, without a branch: unusable points (NaN, too far) get the largest
    // key, which no voxel has (each field of a voxel key is at most 2^bits - 2), so they sort to
    // the end and are cut off there.
    const std::uint64_t unusable_key = (std::uint64_t{1} << layout.total_bits) - 1;
    items.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const Eigen::Vector3f& p = cloud[i];
        const bool usable = IsUsable(p, max_coordinate_m);
        const Eigen::Vector3f q = usable ? p : Eigen::Vector3f::Zero();  // no NaN to convert
        const Eigen::Array3i index(FloorToInt(q.x() * inverse_voxel_size),
                                   FloorToInt(q.y() * inverse_voxel_size),
                                   FloorToInt(q.z() * inverse_voxel_size));
        items[i] =
            codec.Make(usable ? layout.Key(index) : unusable_key, static_cast<std::uint32_t>(i));
    }
    RadixSort(items, layout.total_bits, scratch, ws.digit_counts,
              [&codec](const Item& item) { return codec.Key(item); });
    items.resize(points_used);
    ws.blocks.clear();
    for (std::size_t i = 0; i < items.size();) {
        KeyedMoments block{codec.Key(items[i]), {}};
        for (; i < items.size() && codec.Key(items[i]) == block.key; ++i) {
            const Eigen::Vector3f& p = cloud[codec.Index(items[i])];
            block.moments.Add(p.cast<double>());
        }
        ws.blocks.push_back(block);
    }
}

// Fills ws.blocks with the moments of every occupied voxel, sorted by key.
void BinIntoVoxels(const PointCloud& cloud, double voxel_size_m, NdtCellStats& stats,
                   KeyLayout& layout, Workspace& ws) {
    const double inverse_voxel_size = 1.0 / voxel_size_m;
    const auto max_coordinate_m =
        static_cast<float>(std::min(kMaxCoordinate_m, kMaxVoxelIndex * voxel_size_m));
    Eigen::Array3i lo;
    Eigen::Array3i hi;
    ws.blocks.clear();
    if (!VoxelBounds(cloud, inverse_voxel_size, max_coordinate_m, stats, lo, hi)) return;
    layout = KeyLayout(lo, hi);
    const int index_bits = BitsFor(cloud.size());
    if (layout.total_bits + index_bits <= 64) {
        SortAndSumVoxels(cloud, inverse_voxel_size, max_coordinate_m, layout, stats.points_used,
                         PackedItems{index_bits}, ws.packed, ws.packed_scratch, ws);
    } else {
        SortAndSumVoxels(cloud, inverse_voxel_size, max_coordinate_m, layout, stats.points_used,
                         PairItems{}, ws.pairs, ws.pairs_scratch, ws);
    }
}

// Box sum of width 2 along one axis: emit(k, in[k] + in[k + step]) for every k where either is
// present, in key order. Both `in` and `in` shifted by -step are sorted, so one merge pass
// suffices.
template <typename Emit>
void PairSumAlongAxis(const std::vector<KeyedMoments>& in, std::uint64_t step, Emit emit) {
    std::size_t a = 0;  // walks keys k = in[a].key   (the cell's own voxel)
    std::size_t b = 0;  // walks keys k = in[b].key - step (the cell's upper neighbour)
    while (a < in.size() || b < in.size()) {
        const std::uint64_t key_a = a < in.size() ? in[a].key : UINT64_MAX;
        const std::uint64_t key_b = b < in.size() ? in[b].key - step : UINT64_MAX;
        const std::uint64_t key = std::min(key_a, key_b);
        Moments sum;
        if (key_a == key) sum += in[a++].moments;
        if (key_b == key) sum += in[b++].moments;
        emit(key, sum);
    }
}

// A covariance from raw moments carries a rounding error of a few epsilon times sum x^2 / (n - 1)
// (measured: up to ~5 epsilon |mean|^2 for identical points). A spread below this many times
// that, 3e-9 m^2 at 120 m, cannot be told from none: the points coincide. Real surfaces spread
// 1e-6 m^2 and more (1 mm of noise); no LiDAR measures finer than the cutoff, although float
// coordinates 120 m away could hold spreads down to ~1e-11 m^2.
constexpr double kCancellationMargin = 1000.0 * std::numeric_limits<double>::epsilon();

// Unbiased covariance from raw moments: (sum x x^T - n mean mean^T) / (n - 1); exactly zero when
// the spread is within the rounding error of that difference, so that coinciding points come out
// degenerate wherever they lie, instead of a shape made of rounding noise.
struct MeanAndCovariance {
    double n;
    Eigen::Vector3d mean_m;
    double xx, xy, xz, yy, yz, zz;

    explicit MeanAndCovariance(const Moments& moments) {
        const auto& m = moments.m;
        n = m[0];
        mean_m = Eigen::Vector3d(m[1], m[2], m[3]) / n;
        const double inverse_dof = 1.0 / (n - 1.0);
        xx = (m[4] - m[1] * mean_m.x()) * inverse_dof;
        xy = (m[5] - m[1] * mean_m.y()) * inverse_dof;
        xz = (m[6] - m[1] * mean_m.z()) * inverse_dof;
        yy = (m[7] - m[2] * mean_m.y()) * inverse_dof;
        yz = (m[8] - m[2] * mean_m.z()) * inverse_dof;
        zz = (m[9] - m[3] * mean_m.z()) * inverse_dof;
        const double rounding = kCancellationMargin * (m[4] + m[7] + m[9]) * inverse_dof;
        if (xx + yy + zz <= rounding) xx = xy = xz = yy = yz = zz = 0.0;
    }
};

// The grid of ComputeNdtCells; `sink(moments)` receives every cell with at least `min_points`
// points, in key order.
template <typename Sink>
void ForEachCell(const PointCloud& cloud, double cell_size_m, int min_points, NdtCellStats* stats,
                 Sink sink) {
    if (!(cell_size_m >= 0.01 && cell_size_m <= 100.0)) {
        throw ConfigError("ndt.cell_size_m must be in [0.01, 100] m, got " +
                          std::to_string(cell_size_m));
    }
    if (min_points < 2) {
        throw ConfigError("ndt.min_points_per_cell must be >= 2, got " +
                          std::to_string(min_points));
    }
    if (cloud.size() > UINT32_MAX) {
        throw ConfigError("NDT cells: a scan of " + std::to_string(cloud.size()) +
                          " points exceeds the 2^32 points one grid indexes");
    }
    NdtCellStats local_stats;
    NdtCellStats& s = stats != nullptr ? *stats : local_stats;
    s = {};
    KeyLayout layout(Eigen::Array3i::Zero(), Eigen::Array3i::Zero());
    Workspace& ws = ThreadWorkspace();
    BinIntoVoxels(cloud, cell_size_m / 2.0, s, layout, ws);
    for (int axis = 0; axis < 2; ++axis) {
        ws.scratch.clear();
        PairSumAlongAxis(ws.blocks, layout.step[axis], [&ws](std::uint64_t key, const Moments& m) {
            ws.scratch.push_back({key, m});
        });
        ws.blocks.swap(ws.scratch);
    }
    // The last pass hands the cells straight to the sink instead of storing them all.
    const auto enough = static_cast<double>(min_points);
    PairSumAlongAxis(ws.blocks, layout.step[2], [&](std::uint64_t, const Moments& m) {
        if (m.m[0] < enough) {
            ++s.sparse_cells;
        } else {
            sink(m);
        }
    });
}

}  // namespace

void NdtCellColumns::clear() {
    for (auto* column : {&mean_x_m, &mean_y_m, &mean_z_m, &cov_xx_m2, &cov_xy_m2, &cov_xz_m2,
                         &cov_yy_m2, &cov_yz_m2, &cov_zz_m2}) {
        column->clear();
    }
    point_count.clear();
}

NdtCell NdtCellColumns::Cell(std::size_t i) const {
    NdtCell cell;
    cell.point_count = point_count[i];
    cell.mean_m = {mean_x_m[i], mean_y_m[i], mean_z_m[i]};
    cell.covariance_m2 << cov_xx_m2[i], cov_xy_m2[i], cov_xz_m2[i], cov_xy_m2[i], cov_yy_m2[i],
        cov_yz_m2[i], cov_xz_m2[i], cov_yz_m2[i], cov_zz_m2[i];
    return cell;
}

std::vector<NdtCell> ComputeNdtCells(const PointCloud& cloud, double cell_size_m, int min_points,
                                     NdtCellStats* stats) {
    std::vector<NdtCell> cells;
    ForEachCell(cloud, cell_size_m, min_points, stats, [&cells](const Moments& moments) {
        const MeanAndCovariance c(moments);
        NdtCell& cell = cells.emplace_back();
        cell.point_count = static_cast<int>(c.n);
        cell.mean_m = c.mean_m;
        cell.covariance_m2 << c.xx, c.xy, c.xz, c.xy, c.yy, c.yz, c.xz, c.yz, c.zz;
    });
    return cells;
}

void ComputeNdtCellColumns(const PointCloud& cloud, double cell_size_m, int min_points,
                           NdtCellColumns& cells, NdtCellStats* stats) {
    cells.clear();
    ForEachCell(cloud, cell_size_m, min_points, stats, [&cells](const Moments& moments) {
        const MeanAndCovariance c(moments);
        cells.point_count.push_back(static_cast<int>(c.n));
        cells.mean_x_m.push_back(c.mean_m.x());
        cells.mean_y_m.push_back(c.mean_m.y());
        cells.mean_z_m.push_back(c.mean_m.z());
        cells.cov_xx_m2.push_back(c.xx);
        cells.cov_xy_m2.push_back(c.xy);
        cells.cov_xz_m2.push_back(c.xz);
        cells.cov_yy_m2.push_back(c.yy);
        cells.cov_yz_m2.push_back(c.yz);
        cells.cov_zz_m2.push_back(c.zz);
    });
}

}  // namespace lidarloop::core

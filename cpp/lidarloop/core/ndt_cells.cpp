#include "lidarloop/core/ndt_cells.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
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
// absolute coordinates: double keeps the covariance exact to ~1e-12 m^2 even 100 km away.
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

// Sorts (key, index) pairs by key (below 2^bits), stably, so the points of a voxel keep the
// scan's order: least significant digit first, 11 bits per pass (a scan's keys have about 30
// bits: three passes). Unlike std::sort it makes no unpredictable comparisons.
void RadixSortByKey(std::vector<std::pair<std::uint64_t, std::uint32_t>>& items, int bits,
                    std::vector<std::pair<std::uint64_t, std::uint32_t>>& scratch) {
    constexpr int kDigitBits = 11;
    constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
    scratch.resize(items.size());
    std::vector<std::size_t> start(kBuckets);
    for (int shift = 0; shift < bits; shift += kDigitBits) {
        const auto digit = [shift](std::uint64_t key) { return (key >> shift) & (kBuckets - 1); };
        std::fill(start.begin(), start.end(), 0);
        for (const auto& item : items) ++start[digit(item.first)];
        std::size_t offset = 0;
        for (std::size_t& s : start) offset += std::exchange(s, offset);
        for (const auto& item : items) scratch[start[digit(item.first)]++] = item;
        items.swap(scratch);
    }
}

// Scratch memory reused by later calls on the same thread: a scan's grid needs a few MB, and
// fresh allocations of that size cost more in page faults than the arithmetic on them.
struct Workspace {
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed_points;  // (voxel key, point)
    std::vector<std::pair<std::uint64_t, std::uint32_t>> sort_scratch;
    std::vector<KeyedMoments> blocks;
    std::vector<KeyedMoments> scratch;
};

Workspace& ThreadWorkspace() {
    thread_local Workspace workspace;
    return workspace;
}

// Fills ws.blocks with the moments of every occupied voxel, sorted by key.
void BinIntoVoxels(const PointCloud& cloud, double voxel_size_m, NdtCellStats& stats,
                   KeyLayout& layout, Workspace& ws) {
    const double inverse_voxel_size = 1.0 / voxel_size_m;
    const auto max_coordinate_m =
        static_cast<float>(std::min(kMaxCoordinate_m, kMaxVoxelIndex * voxel_size_m));
    const auto index_of = [inverse_voxel_size](const Eigen::Vector3f& p) {
        return Eigen::Array3i(FloorToInt(p.x() * inverse_voxel_size),
                              FloorToInt(p.y() * inverse_voxel_size),
                              FloorToInt(p.z() * inverse_voxel_size));
    };
    // Pass 1: the bounds of the voxel indices, which fix the key layout. Recomputing the indices
    // in pass 2 is cheaper than storing them.
    Eigen::Array3i lo = Eigen::Array3i::Constant(INT32_MAX);
    Eigen::Array3i hi = Eigen::Array3i::Constant(INT32_MIN);
    for (const Eigen::Vector3f& p : cloud) {
        if (!IsUsable(p, max_coordinate_m)) {
            ++stats.points_skipped;
            continue;
        }
        const Eigen::Array3i index = index_of(p);
        lo = lo.min(index);
        hi = hi.max(index);
    }
    stats.points_used = cloud.size() - stats.points_skipped;
    ws.blocks.clear();
    if (stats.points_used == 0) return;
    layout = KeyLayout(lo, hi);
    // Pass 2: sort the points by voxel key and sum the moments of each run of equal keys. This
    // does not depend on the order in which the scanner wrote its points (ring by ring or column
    // by column), unlike a hash table whose lookups miss when consecutive points change voxel.
    auto& keyed = ws.keyed_points;
    keyed.clear();
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const Eigen::Vector3f& p = cloud[i];
        if (!IsUsable(p, max_coordinate_m)) continue;
        keyed.emplace_back(layout.Key(index_of(p)), static_cast<std::uint32_t>(i));
    }
    RadixSortByKey(keyed, layout.total_bits, ws.sort_scratch);
    for (std::size_t i = 0; i < keyed.size();) {
        KeyedMoments block{keyed[i].first, {}};
        for (; i < keyed.size() && keyed[i].first == block.key; ++i) {
            block.moments.Add(cloud[keyed[i].second].cast<double>());
        }
        ws.blocks.push_back(block);
    }
}

// Box sum of width 2 along one axis: out[k] = in[k] + in[k + step], for every k where either is
// present. Both `in` and `in` shifted by -step are sorted, so one merge pass suffices.
void PairSumAlongAxis(const std::vector<KeyedMoments>& in, std::uint64_t step,
                      std::vector<KeyedMoments>& out) {
    out.clear();
    std::size_t a = 0;  // walks keys k = in[a].key   (the cell's own voxel)
    std::size_t b = 0;  // walks keys k = in[b].key - step (the cell's upper neighbour)
    while (a < in.size() || b < in.size()) {
        const std::uint64_t key_a = a < in.size() ? in[a].key : UINT64_MAX;
        const std::uint64_t key_b = b < in.size() ? in[b].key - step : UINT64_MAX;
        const std::uint64_t key = std::min(key_a, key_b);
        KeyedMoments cell{key, {}};
        if (key_a == key) cell.moments += in[a++].moments;
        if (key_b == key) cell.moments += in[b++].moments;
        out.push_back(cell);
    }
}

NdtCell CellFromMoments(const Moments& moments) {
    const auto& m = moments.m;
    const double n = m[0];
    NdtCell cell;
    cell.point_count = static_cast<int>(n);
    cell.mean_m = Eigen::Vector3d(m[1], m[2], m[3]) / n;
    Eigen::Matrix3d sum_outer;
    sum_outer << m[4], m[5], m[6], m[5], m[7], m[8], m[6], m[8], m[9];
    // Unbiased covariance from raw moments: (sum x x^T - n mean mean^T) / (n - 1).
    cell.covariance_m2 = (sum_outer - n * cell.mean_m * cell.mean_m.transpose()) / (n - 1.0);
    return cell;
}

}  // namespace

std::vector<NdtCell> ComputeNdtCells(const PointCloud& cloud, double cell_size_m, int min_points,
                                     NdtCellStats* stats) {
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
    for (const std::uint64_t step : layout.step) {
        PairSumAlongAxis(ws.blocks, step, ws.scratch);
        ws.blocks.swap(ws.scratch);
    }
    std::vector<NdtCell> cells;
    cells.reserve(ws.blocks.size());
    for (const KeyedMoments& block : ws.blocks) {
        if (block.moments.m[0] < static_cast<double>(min_points)) {
            ++s.sparse_cells;
            continue;
        }
        cells.push_back(CellFromMoments(block.moments));
    }
    return cells;
}

}  // namespace lidarloop::core

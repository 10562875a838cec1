#include "lidarloop/core/ndt_cells.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

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
        const double values[10] = {1.0,         p.x(),       p.y(),       p.z(),
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

// The point travels with its key so that the moments are summed in one sequential sweep.
struct KeyedPoint {
    std::uint64_t key;
    Eigen::Vector3f point;
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

// LSD radix sort by key on the low `key_bits` bits, 11 bits per pass.
void RadixSortByKey(std::vector<KeyedPoint>& items, int key_bits) {
    constexpr int kDigitBits = 11;
    constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
    std::vector<KeyedPoint> buffer(items.size());
    std::vector<std::size_t> offsets(kBuckets);
    for (int shift = 0; shift < key_bits; shift += kDigitBits) {
        std::fill(offsets.begin(), offsets.end(), 0);
        for (const KeyedPoint& item : items) ++offsets[(item.key >> shift) & (kBuckets - 1)];
        std::size_t running = 0;
        for (std::size_t& offset : offsets) running += std::exchange(offset, running);
        for (const KeyedPoint& item : items) {
            buffer[offsets[(item.key >> shift) & (kBuckets - 1)]++] = item;
        }
        items.swap(buffer);
    }
}

bool IsUsable(const Eigen::Vector3f& p, float max_coordinate_m) {
    return p.allFinite() && p.cwiseAbs().maxCoeff() <= max_coordinate_m;
}

Eigen::Array3i VoxelIndex(const Eigen::Vector3f& p, double inverse_voxel_size) {
    return (p.cast<double>().array() * inverse_voxel_size).floor().cast<int>();
}

std::vector<KeyedMoments> BinIntoVoxels(const PointCloud& cloud, double voxel_size_m,
                                        NdtCellStats& stats, KeyLayout& layout) {
    const double inverse_voxel_size = 1.0 / voxel_size_m;
    const auto max_coordinate_m =
        static_cast<float>(std::min(kMaxCoordinate_m, kMaxVoxelIndex * voxel_size_m));
    // Pass 1: the index bounds, which fix the key layout.
    Eigen::Array3i lo = Eigen::Array3i::Constant(INT32_MAX);
    Eigen::Array3i hi = Eigen::Array3i::Constant(INT32_MIN);
    for (const Eigen::Vector3f& p : cloud) {
        if (!IsUsable(p, max_coordinate_m)) {
            ++stats.points_skipped;
            continue;
        }
        const Eigen::Array3i index = VoxelIndex(p, inverse_voxel_size);
        lo = lo.min(index);
        hi = hi.max(index);
    }
    stats.points_used = cloud.size() - stats.points_skipped;
    if (stats.points_used == 0) return {};
    layout = KeyLayout(lo, hi);
    // Pass 2: keys, then sort, then one sweep summing the moments of equal keys.
    std::vector<KeyedPoint> keyed;
    keyed.reserve(stats.points_used);
    for (const Eigen::Vector3f& p : cloud) {
        if (IsUsable(p, max_coordinate_m)) {
            keyed.push_back({layout.Key(VoxelIndex(p, inverse_voxel_size)), p});
        }
    }
    RadixSortByKey(keyed, layout.total_bits);
    std::vector<KeyedMoments> voxels;
    for (const KeyedPoint& kp : keyed) {
        if (voxels.empty() || voxels.back().key != kp.key) voxels.push_back({kp.key, {}});
        voxels.back().moments.Add(kp.point.cast<double>());
    }
    return voxels;
}

// Box sum of width 2 along one axis: out[k] = in[k] + in[k + step], for every k where either is
// present. Both `in` and `in` shifted by -step are sorted, so one merge pass suffices.
std::vector<KeyedMoments> PairSumAlongAxis(const std::vector<KeyedMoments>& in,
                                           std::uint64_t step) {
    std::vector<KeyedMoments> out;
    out.reserve(in.size() * 2);
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
    return out;
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
        throw ConfigError("ndt.min_points_per_cell must be >= 2, got " + std::to_string(min_points));
    }
    NdtCellStats local_stats;
    NdtCellStats& s = stats != nullptr ? *stats : local_stats;
    s = {};
    KeyLayout layout(Eigen::Array3i::Zero(), Eigen::Array3i::Zero());
    std::vector<KeyedMoments> blocks = BinIntoVoxels(cloud, cell_size_m / 2.0, s, layout);
    for (const std::uint64_t step : layout.step) blocks = PairSumAlongAxis(blocks, step);
    std::vector<NdtCell> cells;
    cells.reserve(blocks.size() / 4);
    for (const KeyedMoments& block : blocks) {
        if (block.moments.m[0] < static_cast<double>(min_points)) {
            ++s.sparse_cells;
            continue;
        }
        cells.push_back(CellFromMoments(block.moments));
    }
    return cells;
}

}  // namespace lidarloop::core

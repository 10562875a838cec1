#include "lidarloop/core/voxel_grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

// Cells beyond this many voxels from the origin are skipped: far inside int64, and beyond any
// scan placed in any frame (1e8 m, the pose readers' bound, at 1 micrometre voxels).
constexpr double kMaxCell = 1e15;
constexpr std::size_t kMinBuckets = 64;

std::uint64_t Hash(std::int64_t x, std::int64_t y, std::int64_t z) {
    // Teschner et al.'s spatial hash primes, then a Fibonacci multiply to spread the high bits.
    const auto h = static_cast<std::uint64_t>(x) * 73856093u ^
                   static_cast<std::uint64_t>(y) * 19349663u ^
                   static_cast<std::uint64_t>(z) * 83492791u;
    return h * 0x9E3779B97F4A7C15ull;
}

// floor(x) for |x| <= kMaxCell, exactly: std::floor is a call into libm on baseline x86-64, three
// per point of every scan prepared for verification.
std::int64_t FloorToInt(double x) {
    const auto truncated = static_cast<std::int64_t>(x);
    return truncated - (x < static_cast<double>(truncated) ? 1 : 0);
}

}  // namespace

VoxelGrid::VoxelGrid(double voxel_m) : voxel_m_(voxel_m) {
    if (!std::isfinite(voxel_m) || voxel_m <= 0.0) {
        throw ConfigError("the voxel size must be a finite number > 0 m, got " +
                          std::to_string(voxel_m));
    }
    table_.assign(kMinBuckets, 0);
}

bool VoxelGrid::CellOf(const Eigen::Vector3d& point, Cell& cell) const {
    const Eigen::Vector3d scaled = point / voxel_m_;
    // Written so that NaN fails too.
    if (!(scaled.cwiseAbs().maxCoeff() <= kMaxCell)) return false;
    cell = {FloorToInt(scaled.x()), FloorToInt(scaled.y()), FloorToInt(scaled.z())};
    return true;
}

std::size_t VoxelGrid::BucketOf(const Cell& cell) const {
    return Hash(cell.x, cell.y, cell.z) >> 16 & (table_.size() - 1);
}

bool VoxelGrid::Add(const Eigen::Vector3d& point, double value) {
    Cell cell;
    if (!CellOf(point, cell)) return false;
    Entry& entry = !entries_.empty() && cell == last_cell_ ? entries_[last_entry_] : EntryOf(cell);
    entry.point += point;
    entry.value += value;
    ++entry.count;
    return true;
}

std::size_t VoxelGrid::AddAll(std::span<const Eigen::Vector3d> points, double value) {
    constexpr std::size_t kBatch = 16;
    std::size_t added = 0;
    std::array<Cell, kBatch> cells;
    std::array<bool, kBatch> placed{};
    for (std::size_t start = 0; start < points.size(); start += kBatch) {
        const std::size_t n = std::min(kBatch, points.size() - start);
        // Touch the buckets, then the voxels they name, then add: the memory loads of a batch
        // overlap. Only hints: a table that grows meanwhile is looked up afresh.
        for (std::size_t k = 0; k < n; ++k) {
            placed[k] = CellOf(points[start + k], cells[k]);
            if (placed[k]) __builtin_prefetch(&table_[BucketOf(cells[k])]);
        }
        for (std::size_t k = 0; k < n; ++k) {
            const std::uint32_t entry = placed[k] ? table_[BucketOf(cells[k])] : 0;
            if (entry != 0) __builtin_prefetch(&entries_[entry - 1]);
        }
        for (std::size_t k = 0; k < n; ++k) {
            if (!placed[k]) continue;
            Entry& entry = EntryOf(cells[k]);
            entry.point += points[start + k];
            entry.value += value;
            ++entry.count;
            ++added;
        }
    }
    return added;
}

VoxelGrid::Entry& VoxelGrid::EntryOf(const Cell& cell) {
    const std::size_t mask = table_.size() - 1;
    std::size_t b = Hash(cell.x, cell.y, cell.z) >> 16 & mask;
    for (; table_[b] != 0; b = (b + 1) & mask) {
        if (entries_[table_[b] - 1].cell == cell) {
            last_cell_ = cell;
            last_entry_ = table_[b] - 1;
            return entries_[last_entry_];
        }
    }
    if (entries_.size() >= std::numeric_limits<std::uint32_t>::max() - 1) {
        throw Error("a voxel grid of more than 4 billion voxels");
    }
    entries_.push_back({cell, Eigen::Vector3d::Zero(), 0.0, 0});
    table_[b] = static_cast<std::uint32_t>(entries_.size());
    // At most half full: short probe sequences.
    if (2 * entries_.size() > table_.size()) Rehash(2 * table_.size());
    last_cell_ = cell;
    last_entry_ = entries_.size() - 1;
    return entries_.back();
}

void VoxelGrid::Rehash(std::size_t buckets) {
    table_.assign(buckets, 0);
    const std::size_t mask = buckets - 1;
    for (std::size_t v = 0; v < entries_.size(); ++v) {
        const Cell& cell = entries_[v].cell;
        std::size_t b = Hash(cell.x, cell.y, cell.z) >> 16 & mask;
        while (table_[b] != 0) b = (b + 1) & mask;
        table_[b] = static_cast<std::uint32_t>(v + 1);
    }
}

void VoxelGrid::Reserve(std::size_t voxels) {
    std::size_t buckets = table_.size();
    while (buckets < 2 * voxels) buckets *= 2;
    entries_.reserve(voxels);
    if (buckets != table_.size()) Rehash(buckets);
}

void VoxelGrid::Coarsen() {
    std::vector<Entry> fine = std::move(entries_);
    entries_.clear();
    table_.assign(kMinBuckets, 0);
    voxel_m_ *= 2.0;
    for (const Entry& from : fine) {
        // Arithmetic shift: floor division by 2, also for negative cells.
        Entry& to = EntryOf({from.cell.x >> 1, from.cell.y >> 1, from.cell.z >> 1});
        to.point += from.point;
        to.value += from.value;
        to.count += from.count;
    }
}

std::vector<Voxel> VoxelGrid::Voxels() const {
    std::vector<Voxel> voxels;
    voxels.reserve(entries_.size());
    for (const Entry& e : entries_) {
        const auto n = static_cast<double>(e.count);
        voxels.push_back({e.point / n, e.value / n, e.count});
    }
    return voxels;
}

std::size_t VoxelGrid::MemoryBytes() const {
    return entries_.capacity() * sizeof(Entry) + table_.capacity() * sizeof(std::uint32_t);
}

}  // namespace lidarloop::core

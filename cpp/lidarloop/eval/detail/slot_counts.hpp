#pragma once

// Counters of StreamedPairwise's slots (negatives between two positives' distances), in a
// header of their own so that the tests can reach the rare carry past 2^32.

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace lidarloop::eval::detail {

// 64-bit counters in 4 bytes each: there are twice as many slots as distinct positive distances
// (of which there are at most as many as positives: 92 M at 100,000 simulated scans and the
// 10 m rule), and almost every slot stays far below 2^32. The few that pass it keep their
// carries aside. Not thread-safe.
class SlotCounts {
public:
    // `size` counters, all 0.
    void Assign(std::size_t size) {
        low_.assign(size, 0);
        carries_.clear();
    }
    // Adds `count` (< 2^32) to counter k.
    void Add(std::size_t k, std::uint64_t count) {
        const std::uint32_t before = low_[k];
        low_[k] = before + static_cast<std::uint32_t>(count);
        if (low_[k] < before) ++carries_[k];
    }
    std::uint64_t operator[](std::size_t k) const {
        const auto carry = carries_.find(k);
        const std::uint64_t high = carry == carries_.end() ? 0 : carry->second;
        return (high << 32) | low_[k];
    }
    std::size_t size() const { return low_.size(); }
    std::uint64_t front() const { return (*this)[0]; }
    std::uint64_t back() const { return (*this)[size() - 1]; }

private:
    std::vector<std::uint32_t> low_;
    std::unordered_map<std::size_t, std::uint64_t> carries_;
};

}  // namespace lidarloop::eval::detail

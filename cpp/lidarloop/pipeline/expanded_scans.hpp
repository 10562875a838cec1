#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/prepared_scan.hpp"

namespace lidarloop::pipeline {

/// The most recently used scans of a sequence, expanded from their compact form. Expanding
/// decodes the points and builds two search grids, about 0.13 ms for an HDL-64E scan, and a query's
/// candidates are mostly the previous query's: with this cache a detector expands a scan a few
/// times in a run instead of once for every pair it is in. Thread-safe. The scan at an index
/// must not change while the cache holds it (sequences only grow).
class ExpandedScans {
public:
    /// Keeps at most `capacity` scans (> 0; about 214 kB each at the default reduction).
    explicit ExpandedScans(std::size_t capacity = kDefaultCapacity);

    /// scans[index].Expand(), from the cache when it holds it.
    registration::PreparedScan Get(const std::vector<registration::CompactPreparedScan>& scans,
                                   std::size_t index);

    std::size_t hits() const;
    std::size_t misses() const;

    /// Two threads' queries of ten candidates each, with room to spare.
    static constexpr std::size_t kDefaultCapacity = 64;

private:
    struct Entry {
        std::size_t index = 0;
        registration::PreparedScan scan;
        std::uint64_t last_used = 0;
    };

    std::size_t capacity_;
    mutable std::mutex mutex_;
    std::vector<Entry> entries_;  // unordered; a linear search of <= capacity_ is cheap
    std::uint64_t clock_ = 0;
    std::size_t hits_ = 0;
    std::size_t misses_ = 0;
};

}  // namespace lidarloop::pipeline

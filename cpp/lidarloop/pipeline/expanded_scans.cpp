#include "lidarloop/pipeline/expanded_scans.hpp"

#include <algorithm>

#include "lidarloop/core/error.hpp"

namespace lidarloop::pipeline {

ExpandedScans::ExpandedScans(std::size_t capacity) : capacity_(capacity) {
    if (capacity == 0) throw core::ConfigError("ExpandedScans: the capacity must be > 0");
    entries_.reserve(capacity);
}

registration::PreparedScan ExpandedScans::Get(
    const std::vector<registration::CompactPreparedScan>& scans, std::size_t index) {
    {
        const std::lock_guard lock(mutex_);
        const auto found = std::find_if(entries_.begin(), entries_.end(),
                                        [&](const Entry& e) { return e.index == index; });
        if (found != entries_.end()) {
            found->last_used = ++clock_;
            ++hits_;
            return found->scan;  // shares the points and trees
        }
        ++misses_;
    }
    // Expanded without the lock: two threads never wait for each other's expansion.
    registration::PreparedScan scan = scans.at(index).Expand();
    const std::lock_guard lock(mutex_);
    const bool present = std::any_of(entries_.begin(), entries_.end(),
                                     [&](const Entry& e) { return e.index == index; });
    if (!present) {
        if (entries_.size() < capacity_) {
            entries_.push_back({index, scan, ++clock_});
        } else {
            auto oldest = std::min_element(
                entries_.begin(), entries_.end(),
                [](const Entry& a, const Entry& b) { return a.last_used < b.last_used; });
            *oldest = {index, scan, ++clock_};
        }
    }
    return scan;
}

std::size_t ExpandedScans::hits() const {
    const std::lock_guard lock(mutex_);
    return hits_;
}

std::size_t ExpandedScans::misses() const {
    const std::lock_guard lock(mutex_);
    return misses_;
}

}  // namespace lidarloop::pipeline

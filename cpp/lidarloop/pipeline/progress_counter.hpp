#pragma once

#include <cstddef>
#include <functional>
#include <mutex>

namespace lidarloop::pipeline {

/// Told how many of a stage's items are done: (done, total).
using ProgressReport = std::function<void(std::size_t done, std::size_t total)>;

/// Counts the items that worker threads finish and tells `report` each new count, one call at a
/// time and in rising order, so that the last call is (total, total). Workers finish out of
/// order; without the lock a stale count could be told after the final one.
class ProgressCounter {
public:
    ProgressCounter(ProgressReport report, std::size_t total)
        : report_(std::move(report)), total_(total) {}

    /// Thread-safe: adds `items` finished items and tells the new count.
    void Add(std::size_t items = 1) {
        if (!report_) return;
        const std::lock_guard<std::mutex> lock(mutex_);
        done_ += items;
        report_(done_, total_);
    }

private:
    ProgressReport report_;
    std::size_t total_;
    std::size_t done_ = 0;
    std::mutex mutex_;
};

}  // namespace lidarloop::pipeline

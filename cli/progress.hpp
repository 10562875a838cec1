#pragma once

#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

#include "lidarloop/app/progress.hpp"

namespace lidarloop::cli {

/// Shows a run's progress as a one-line bar per stage on stderr, cleared when the stage ends.
/// Silent when stderr is not a terminal or when asked to be quiet, so logs and pipes stay clean.
/// Thread-safe; redraws at most ten times a second. Must outlive the runs it is given to.
class ProgressPrinter {
public:
    explicit ProgressPrinter(bool quiet);
    ~ProgressPrinter();
    ProgressPrinter(const ProgressPrinter&) = delete;
    ProgressPrinter& operator=(const ProgressPrinter&) = delete;

    /// The callback to put into a run's request (empty when silent).
    app::Progress Callback();

private:
    void Update(const std::string& stage, std::size_t done, std::size_t total);
    void Draw(std::size_t done, std::size_t total, std::chrono::steady_clock::time_point now);
    void Clear();

    bool enabled_;
    std::mutex mutex_;
    std::string stage_;
    std::string finished_;  // a worker may report late on a finished stage
    bool drawn_ = false;
    std::chrono::steady_clock::time_point start_;
    std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace lidarloop::cli

#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>

#include "lidarloop/app/progress.hpp"

namespace lidarloop::cli {

/// A one-line progress bar on stderr for long runs. Silent when stderr is not a terminal or when
/// asked to be quiet, so logs and pipes stay clean. Update is thread-safe and redraws at most
/// ten times a second.
class ProgressBar {
public:
    ProgressBar(std::string label, bool quiet);
    ~ProgressBar();
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;

    void Update(std::size_t done, std::size_t total);
    /// Clears the line (called by the destructor too).
    void Finish();

private:
    std::string label_;
    bool enabled_;
    bool drawn_ = false;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point start_;
    std::chrono::steady_clock::time_point last_draw_;
};

/// Shows a run layer's progress as one bar per stage. Must outlive the runs it is given to.
class ProgressPrinter {
public:
    explicit ProgressPrinter(bool quiet) : quiet_(quiet) {}
    /// The callback to put into a run's request.
    app::Progress Callback();

private:
    void Update(const std::string& stage, std::size_t done, std::size_t total);

    bool quiet_;
    std::mutex mutex_;
    std::string stage_;
    std::string finished_;
    std::unique_ptr<ProgressBar> bar_;
};

}  // namespace lidarloop::cli

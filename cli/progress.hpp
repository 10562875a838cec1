#pragma once

#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

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

}  // namespace lidarloop::cli

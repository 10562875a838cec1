#include "progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace lidarloop::cli {

ProgressBar::ProgressBar(std::string label, bool quiet)
    : label_(std::move(label)),
      enabled_(!quiet && isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() { Finish(); }

void ProgressBar::Update(std::size_t done, std::size_t total) {
    if (!enabled_ || total == 0) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (drawn_ && done < total && now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    drawn_ = true;
    constexpr int kWidth = 30;
    const double fraction = static_cast<double>(done) / static_cast<double>(total);
    const int filled = static_cast<int>(fraction * kWidth);
    const double elapsed_s = std::chrono::duration<double>(now - start_).count();
    const double remaining_s = done > 0 ? elapsed_s * (1.0 - fraction) / fraction : 0.0;
    std::fprintf(stderr, "\r%s [%.*s%*s] %zu/%zu  %.0f s left ", label_.c_str(), filled,
                 "##############################", kWidth - filled, "", done, total, remaining_s);
    std::fflush(stderr);
}

void ProgressBar::Finish() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!drawn_) return;
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
    drawn_ = false;
}

app::Progress ProgressPrinter::Callback() {
    if (quiet_) return {};
    return [this](const std::string& stage, std::size_t done, std::size_t total) {
        Update(stage, done, total);
    };
}

void ProgressPrinter::Update(const std::string& stage, std::size_t done, std::size_t total) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (stage == finished_) return;  // a worker reporting late on a finished stage
    if (!bar_ || stage != stage_) {
        bar_.reset();  // clears the previous stage's line first
        stage_ = stage;
        bar_ = std::make_unique<ProgressBar>(stage, quiet_);
    }
    bar_->Update(done, total);
    if (done >= total) {
        bar_.reset();
        finished_ = stage;
    }
}

}  // namespace lidarloop::cli

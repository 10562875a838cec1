#include "progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace lidarloop::cli {

ProgressPrinter::ProgressPrinter(bool quiet) : enabled_(!quiet && isatty(STDERR_FILENO) != 0) {}

ProgressPrinter::~ProgressPrinter() {
    const std::lock_guard<std::mutex> lock(mutex_);
    Clear();
}

app::Progress ProgressPrinter::Callback() {
    if (!enabled_) return {};
    return [this](const std::string& stage, std::size_t done, std::size_t total) {
        Update(stage, done, total);
    };
}

void ProgressPrinter::Update(const std::string& stage, std::size_t done, std::size_t total) {
    if (total == 0) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    if (stage == finished_) return;
    const auto now = std::chrono::steady_clock::now();
    if (stage != stage_) {
        Clear();
        stage_ = stage;
        start_ = now;
    }
    if (done >= total) {
        Clear();
        finished_ = stage;
        return;
    }
    if (drawn_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
    Draw(done, total, now);
}

void ProgressPrinter::Draw(std::size_t done, std::size_t total,
                           std::chrono::steady_clock::time_point now) {
    last_draw_ = now;
    drawn_ = true;
    constexpr int kWidth = 30;
    const double fraction = static_cast<double>(done) / static_cast<double>(total);
    const int filled = static_cast<int>(fraction * kWidth);
    const double elapsed_s = std::chrono::duration<double>(now - start_).count();
    const double remaining_s = done > 0 ? elapsed_s * (1.0 - fraction) / fraction : 0.0;
    std::fprintf(stderr, "\r%s [%.*s%*s] %zu/%zu  %.0f s left ", stage_.c_str(), filled,
                 "##############################", kWidth - filled, "", done, total, remaining_s);
    std::fflush(stderr);
}

void ProgressPrinter::Clear() {
    if (!drawn_) return;
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
    drawn_ = false;
}

}  // namespace lidarloop::cli

#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <utility>

#include "lidarloop/pipeline/progress_counter.hpp"

namespace lidarloop::app {

/// Told how far a run has come: (stage, items done, items in the stage), e.g. ("describing
/// (height)", 120, 320). Called from worker threads, one call at a time, with `done` rising within
/// a stage; a stage's last call has done == total. Empty: nobody is told.
using Progress = std::function<void(const std::string& stage, std::size_t done, std::size_t total)>;

/// `progress` for one stage as a (done, total) report; empty when `progress` is.
inline pipeline::ProgressReport StageReport(const Progress& progress, std::string stage) {
    if (!progress) return {};
    return [progress, stage = std::move(stage)](std::size_t done, std::size_t total) {
        progress(stage, done, total);
    };
}

}  // namespace lidarloop::app

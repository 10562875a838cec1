#pragma once

#include <cstddef>
#include <functional>
#include <string>

namespace lidarloop::app {

/// Told how far a run has come: (stage, items done, items in the stage), e.g. ("describing
/// (height)", 120, 320). Called from worker threads, possibly at once from several; a stage ends
/// when done == total. Empty: nobody is told.
using Progress = std::function<void(const std::string& stage, std::size_t done, std::size_t total)>;

}  // namespace lidarloop::app

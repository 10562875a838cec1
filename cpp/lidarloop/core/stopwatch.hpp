#pragma once

#include <chrono>

namespace lidarloop::core {

/// Wall-clock seconds since construction.
class Stopwatch {
public:
    double Seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }

private:
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// CPU seconds of the calling thread since construction: what a step costs on one core, whatever
/// else the machine does (wall time is inflated by other processes). Read on the thread that
/// constructed it.
class ThreadCpuStopwatch {
public:
    ThreadCpuStopwatch() : start_(Now()) {}
    double Seconds() const { return Now() - start_; }

private:
    static double Now();
    double start_;
};

}  // namespace lidarloop::core

#include "lidarloop/core/stopwatch.hpp"

#include <time.h>

namespace lidarloop::core {

double ThreadCpuStopwatch::Now() {
    timespec now{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
    return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

}  // namespace lidarloop::core

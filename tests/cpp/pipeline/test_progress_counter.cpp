#include "lidarloop/pipeline/progress_counter.hpp"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace lidarloop::pipeline {
namespace {

TEST(ProgressCounter, WorkersAreToldOneAtATimeInRisingOrder) {
    constexpr std::size_t kItems = 5000;
    std::vector<std::size_t> told;
    std::atomic<int> inside{0};
    std::atomic<bool> overlapped{false};
    ProgressCounter counter(
        [&](std::size_t done, std::size_t total) {
            if (inside.fetch_add(1) != 0) overlapped = true;
            EXPECT_EQ(total, kItems);
            told.push_back(done);
            std::this_thread::yield();  // widens the window in which a second call would overlap
            inside.fetch_sub(1);
        },
        kItems);
    tbb::parallel_for(std::size_t{0}, kItems, [&](std::size_t) { counter.Add(); });
    EXPECT_FALSE(overlapped);
    ASSERT_EQ(told.size(), kItems);
    for (std::size_t k = 0; k < kItems; ++k) ASSERT_EQ(told[k], k + 1) << "call " << k;
}

TEST(ProgressCounter, CountsBatchesAndNeedsNoReport) {
    std::vector<std::size_t> told;
    ProgressCounter counter([&](std::size_t done, std::size_t) { told.push_back(done); }, 10);
    counter.Add(3);
    counter.Add(7);
    EXPECT_EQ(told, (std::vector<std::size_t>{3, 10}));
    ProgressCounter silent({}, 10);
    silent.Add(5);  // nobody is told; no crash
}

}  // namespace
}  // namespace lidarloop::pipeline

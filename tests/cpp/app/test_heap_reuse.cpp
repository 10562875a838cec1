#include <sys/resource.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>

#include "lidarloop/app/heap_reuse.hpp"
#include "test_utils.hpp"

namespace lidarloop::app {
namespace {

long MinorPageFaults() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_minflt;
}

// Three blocks of 12 MiB written and freed together, as a scan's points, voxels and centroids
// are (scaled up, so that glibc's own adjustment cannot keep them): kB faulted in.
long FaultedKilobytesOfOneRound() {
    constexpr std::size_t kBlockBytes = std::size_t{12} << 20;
    const long before = MinorPageFaults();
    std::array<char*, 3> blocks{};
    for (char*& block : blocks) {
        block = static_cast<char*>(std::malloc(kBlockBytes));
        if (block == nullptr) std::abort();
        std::memset(block, 1, kBlockBytes);
        asm volatile("" : : "r"(block) : "memory");  // the writes must happen
    }
    for (char* block : blocks) std::free(block);
    return (MinorPageFaults() - before) * (sysconf(_SC_PAGESIZE) / 1024);
}

TEST(KeepFreedMemoryForReuse, TheAllocatorTakesTheSettings) {
    if (test::kSanitizedBuild) {
        EXPECT_FALSE(KeepFreedMemoryForReuse());  // the sanitizer's allocator refuses them
        return;
    }
    EXPECT_TRUE(KeepFreedMemoryForReuse());
}

// By default glibc trims a freed heap top beyond twice the largest block it has freed (24 MiB
// here), so every round faults all 36 MiB in again (checked); kept, only the first round does.
TEST(KeepFreedMemoryForReuse, FreedScanSizedBlocksAreTouchedWithoutPageFaults) {
    if (test::kSanitizedBuild) GTEST_SKIP() << "the sanitizer's allocator is not glibc's";
    ASSERT_TRUE(KeepFreedMemoryForReuse());
    FaultedKilobytesOfOneRound();
    long faulted_kb = 0;
    for (int round = 0; round < 3; ++round) faulted_kb += FaultedKilobytesOfOneRound();
    EXPECT_LT(faulted_kb, 1024);
}

}  // namespace
}  // namespace lidarloop::app

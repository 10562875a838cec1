#include <algorithm>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/pipeline/expanded_scans.hpp"
#include "registration/registration_test_utils.hpp"

namespace lidarloop::pipeline {
namespace {

std::vector<registration::CompactPreparedScan> CompactScans(std::size_t count) {
    std::vector<registration::CompactPreparedScan> scans;
    for (std::size_t i = 0; i < count; ++i) {
        scans.emplace_back(registration::PrepareScan(test::SyntheticPlace(i + 1),
                                                     registration::ScanReductionConfig{}));
    }
    return scans;
}

void ExpectSameScan(const registration::PreparedScan& actual,
                    const registration::PreparedScan& expected) {
    ASSERT_TRUE(actual.structure && expected.structure);
    EXPECT_EQ(actual.structure->points(), expected.structure->points());
    EXPECT_EQ(actual.structure->normals(), expected.structure->normals());
    EXPECT_EQ(actual.ground->points(), expected.ground->points());
    EXPECT_EQ(actual.structure_distinctive, expected.structure_distinctive);
    EXPECT_EQ(actual.structure_roughness_m, expected.structure_roughness_m);
}

TEST(ExpandedScans, GivesWhatExpandGivesAndExpandsEachScanOnce) {
    const auto scans = CompactScans(4);
    ExpandedScans expanded(4);
    for (int round = 0; round < 3; ++round) {
        for (std::size_t i = 0; i < scans.size(); ++i)
            ExpectSameScan(expanded.Get(scans, i), scans[i].Expand());
    }
    EXPECT_EQ(expanded.misses(), 4u);
    EXPECT_EQ(expanded.hits(), 8u);
}

TEST(ExpandedScans, DropsTheScanUsedLongestAgo) {
    const auto scans = CompactScans(3);
    ExpandedScans expanded(2);
    expanded.Get(scans, 0);
    expanded.Get(scans, 1);
    expanded.Get(scans, 0);  // 1 is now the oldest
    expanded.Get(scans, 2);  // drops 1
    EXPECT_EQ(expanded.misses(), 3u);
    expanded.Get(scans, 0);
    expanded.Get(scans, 2);
    EXPECT_EQ(expanded.misses(), 3u);
    ExpectSameScan(expanded.Get(scans, 1), scans[1].Expand());
    EXPECT_EQ(expanded.misses(), 4u);
}

TEST(ExpandedScans, ThreadsShareItSafely) {
    const auto scans = CompactScans(5);
    ExpandedScans expanded(3);
    std::vector<std::size_t> sizes(400);
    std::vector<std::thread> threads;
    for (std::size_t t = 0; t < 4; ++t) {
        threads.emplace_back([&, t] {
            for (std::size_t k = t; k < sizes.size(); k += 4)
                sizes[k] = expanded.Get(scans, k % scans.size()).structure->size();
        });
    }
    for (std::thread& thread : threads) thread.join();
    for (std::size_t k = 0; k < sizes.size(); ++k)
        EXPECT_EQ(sizes[k], scans[k % scans.size()].Expand().structure->size()) << k;
    EXPECT_EQ(expanded.hits() + expanded.misses(), sizes.size());
}

TEST(ExpandedScans, BadUseIsAClearError) {
    EXPECT_THROW(ExpandedScans(0), core::ConfigError);
    const auto scans = CompactScans(1);
    ExpandedScans expanded;
    EXPECT_THROW(expanded.Get(scans, 1), std::out_of_range);
}

}  // namespace
}  // namespace lidarloop::pipeline

#include <random>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/wasserstein.hpp"
#include "lidarloop/pipeline/cumulative_histograms.hpp"
#include "lidarloop/pipeline/histogram_index.hpp"
#include "pipeline/pipeline_test_utils.hpp"

namespace lidarloop::pipeline {
namespace {

TEST(CumulativeHistograms, DistanceIsRoehlingsWasserstein) {
    const auto histograms = test::ClusteredHistograms(50, 37, 5, 1);
    CumulativeHistograms store(37);
    for (const auto& h : histograms) store.Add(h);
    EXPECT_EQ(store.stride(), 40);
    for (std::size_t i = 0; i < histograms.size(); ++i) {
        for (std::size_t j = 0; j < histograms.size(); ++j) {
            // Float rows hold each cumulative value to 2^-24, so W is exact to ~1e-7, four
            // orders below the thresholds in use (~1e-3).
            const double expected = core::WassersteinDistance(histograms[i], histograms[j]);
            EXPECT_NEAR(store.Distance(i, j), expected, 2e-7);
        }
        EXPECT_EQ(store.Distance(i, i), 0.0);
    }
}

TEST(CumulativeHistograms, RejectsWrongSizes) {
    CumulativeHistograms store(10);
    EXPECT_THROW(store.Add(std::vector<double>(9, 0.1)), core::ConfigError);
    EXPECT_THROW(store.AddRow(std::vector<float>(10, 0.0f)), core::ConfigError);  // stride 16
    EXPECT_THROW(CumulativeHistograms(0), core::ConfigError);
}

void ExpectSame(const std::vector<Neighbor>& a, const std::vector<Neighbor>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].index, b[i].index) << "rank " << i;
        EXPECT_EQ(a[i].distance, b[i].distance) << "rank " << i;
    }
}

TEST(HistogramIndex, ReturnsExactlyTheBruteForceTopK) {
    for (int bins : {16, 100}) {
        const auto histograms = test::ClusteredHistograms(3000, bins, 40, 2);
        CumulativeHistograms store(bins);
        for (const auto& h : histograms) store.Add(h);
        HistogramIndex index(store);
        index.InsertAll();
        const auto queries = test::ClusteredHistograms(100, bins, 40, 2);  // same places
        for (const auto& q : queries) {
            const auto row = store.MakeRow(q);
            for (std::size_t k : {1U, 5U, 50U}) {
                ExpectSame(index.Search(row.data(), k), index.BruteForce(row.data(), k));
            }
        }
    }
}

TEST(HistogramIndex, RespectsEligibilityAndHandlesDuplicates) {
    auto histograms = test::ClusteredHistograms(500, 20, 10, 3);
    const std::vector<std::vector<double>> repeated(histograms.begin(), histograms.begin() + 100);
    histograms.insert(histograms.end(), repeated.begin(), repeated.end());  // exact ties
    CumulativeHistograms store(20);
    HistogramIndex index(store);
    for (const auto& h : histograms) index.Insert(store.Add(h));  // incremental inserts
    const auto even_below_400 = [](std::size_t id) { return id % 2 == 0 && id < 400; };
    for (std::size_t q = 0; q < histograms.size(); q += 7) {
        const auto row = store.MakeRow(histograms[q]);
        const auto found = index.Search(row.data(), 10, even_below_400);
        ExpectSame(found, index.BruteForce(row.data(), 10, even_below_400));
        for (const Neighbor& n : found) EXPECT_TRUE(even_below_400(n.index));
    }
}

TEST(HistogramIndex, EmptyAndZeroK) {
    CumulativeHistograms store(8);
    HistogramIndex index(store);
    const auto row = store.MakeRow(std::vector<double>(8, 0.125));
    EXPECT_TRUE(index.Search(row.data(), 3).empty());
    store.Add(std::vector<double>(8, 0.125));
    index.InsertAll();
    EXPECT_TRUE(index.Search(row.data(), 0).empty());
    ASSERT_EQ(index.Search(row.data(), 3).size(), 1U);
    EXPECT_THROW(index.Insert(0), core::ConfigError);  // already indexed
    EXPECT_THROW(index.Insert(5), core::ConfigError);  // not in the store
}

}  // namespace
}  // namespace lidarloop::pipeline

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/wasserstein.hpp"

namespace lidarloop::core {
namespace {

std::vector<double> RandomHistogram(std::size_t bins, std::mt19937& rng) {
    std::exponential_distribution<double> weight(1.0);
    std::vector<double> h(bins);
    for (double& v : h) v = weight(rng);
    const double total = std::accumulate(h.begin(), h.end(), 0.0);
    for (double& v : h) v /= total;
    return h;
}

// Brute-force optimal transport: both histograms are made of `units` equal unit masses
// (h_k = count_k / units); the earth mover's distance is then the minimum, over all assignments
// of the units of G to the units of H, of the mean distance moved, in bucket widths / b. Trying
// every permutation is exact, and independent of the prefix-sum formula under test.
double BruteForceTransport(const std::vector<int>& g_counts, const std::vector<int>& h_counts) {
    std::vector<int> g_units;
    std::vector<int> h_units;
    for (int k = 0; k < static_cast<int>(g_counts.size()); ++k) {
        g_units.insert(g_units.end(), static_cast<std::size_t>(g_counts[k]), k);
        h_units.insert(h_units.end(), static_cast<std::size_t>(h_counts[k]), k);
    }
    std::sort(h_units.begin(), h_units.end());
    double best = 1e300;
    do {
        double cost = 0.0;
        for (std::size_t u = 0; u < g_units.size(); ++u) cost += std::abs(g_units[u] - h_units[u]);
        best = std::min(best, cost);
    } while (std::next_permutation(h_units.begin(), h_units.end()));
    const double bins = static_cast<double>(g_counts.size());
    return best / static_cast<double>(g_units.size()) / bins;
}

std::vector<double> Normalise(const std::vector<int>& counts) {
    const double total = std::accumulate(counts.begin(), counts.end(), 0.0);
    std::vector<double> h;
    for (int c : counts) h.push_back(c / total);
    return h;
}

TEST(Wasserstein, IdenticalHistogramsHaveZeroDistance) {
    std::mt19937 rng(1);
    for (int trial = 0; trial < 20; ++trial) {
        const auto h = RandomHistogram(100, rng);
        EXPECT_EQ(WassersteinDistance(h, h), 0.0);
    }
}

TEST(Wasserstein, IsSymmetric) {
    std::mt19937 rng(2);
    for (int trial = 0; trial < 50; ++trial) {
        const auto g = RandomHistogram(37, rng);
        const auto h = RandomHistogram(37, rng);
        EXPECT_NEAR(WassersteinDistance(g, h), WassersteinDistance(h, g), 1e-15);
        EXPECT_GT(WassersteinDistance(g, h), 0.0);
    }
}

TEST(Wasserstein, SatisfiesTriangleInequality) {
    std::mt19937 rng(3);
    for (int trial = 0; trial < 200; ++trial) {
        const auto a = RandomHistogram(20, rng);
        const auto b = RandomHistogram(20, rng);
        const auto c = RandomHistogram(20, rng);
        EXPECT_LE(WassersteinDistance(a, c),
                  WassersteinDistance(a, b) + WassersteinDistance(b, c) + 1e-12);
    }
}

TEST(Wasserstein, StaysWithinBoundsOnRandomHistograms) {
    std::mt19937 rng(4);
    for (int trial = 0; trial < 200; ++trial) {
        const auto g = RandomHistogram(64, rng);
        const auto h = RandomHistogram(64, rng);
        const double w = WassersteinDistance(g, h);
        EXPECT_GE(w, 0.0);
        EXPECT_LE(w, 63.0 / 64.0);
    }
}

TEST(Wasserstein, ExtremeHistogramsReachTheMaximum) {
    // All mass in the first versus all in the last bucket: every prefix difference but the last
    // is 1, so W = (b-1)/b, the largest value eq. (6) can take; it tends to the bound 1 of eq. (8).
    for (std::size_t bins : {1U, 2U, 10U, 100U, 1000U}) {
        std::vector<double> first(bins, 0.0);
        std::vector<double> last(bins, 0.0);
        first.front() = 1.0;
        last.back() = 1.0;
        const double expected = static_cast<double>(bins - 1) / static_cast<double>(bins);
        EXPECT_DOUBLE_EQ(WassersteinDistance(first, last), expected) << bins << " bins";
        EXPECT_LT(WassersteinDistance(first, last), 1.0);
    }
}

TEST(Wasserstein, EqualsBruteForceTransportOnSmallHistograms) {
    std::mt19937 rng(5);
    for (int trial = 0; trial < 100; ++trial) {
        const std::size_t bins = 2 + rng() % 5;
        const int units = 1 + static_cast<int>(rng() % 7);
        std::vector<int> g_counts(bins, 0);
        std::vector<int> h_counts(bins, 0);
        for (int u = 0; u < units; ++u) {
            ++g_counts[rng() % bins];
            ++h_counts[rng() % bins];
        }
        EXPECT_NEAR(WassersteinDistance(Normalise(g_counts), Normalise(h_counts)),
                    BruteForceTransport(g_counts, h_counts), 1e-12);
    }
}

TEST(Wasserstein, KnownValueForOneBucketShift) {
    // Moving all mass one bucket costs one bucket width, 1/b of the value range.
    const std::vector<double> g = {0.0, 1.0, 0.0, 0.0};
    const std::vector<double> h = {0.0, 0.0, 1.0, 0.0};
    EXPECT_DOUBLE_EQ(WassersteinDistance(g, h), 0.25);
}

TEST(Wasserstein, RejectsMismatchedOrEmptyHistograms) {
    const std::vector<double> three = {0.2, 0.3, 0.5};
    const std::vector<double> two = {0.5, 0.5};
    const std::vector<double> empty;
    EXPECT_THROW(WassersteinDistance(three, two), ConfigError);
    EXPECT_THROW(WassersteinDistance(empty, empty), ConfigError);
}

TEST(Wasserstein, ClassifierAcceptsAtAndBelowThreshold) {
    EXPECT_TRUE(IsLoop(0.004, 0.005));
    EXPECT_TRUE(IsLoop(0.005, 0.005));
    EXPECT_FALSE(IsLoop(0.0051, 0.005));
}

}  // namespace
}  // namespace lidarloop::core

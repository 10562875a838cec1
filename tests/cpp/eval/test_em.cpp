#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/em.hpp"
#include "test_utils.hpp"

namespace lidarloop::eval {
namespace {

const std::vector<GaussianComponent> kTruth{
    {0.30, 0.05, 0.010},  // overlapping scans: small differences
    {0.50, 0.15, 0.030},  // non-overlapping scans
    {0.20, 0.40, 0.060},  // failures of the descriptor
};

std::vector<double> MixtureSample(const std::vector<GaussianComponent>& truth, std::size_t n,
                                  unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::vector<double> sample(n);
    for (double& x : sample) {
        double u = unit(rng);
        std::size_t c = 0;
        while (c + 1 < truth.size() && u > truth[c].weight) u -= truth[c++].weight;
        x = truth[c].mean + truth[c].stddev * normal(rng);
    }
    return sample;
}

// Crossing of the weighted densities between the means by bisection.
double NumericCrossing(const GaussianComponent& a, const GaussianComponent& b) {
    double lo = a.mean;
    double hi = b.mean;
    const auto f = [&](double x) { return a.WeightedDensity(x) - b.WeightedDensity(x); };
    EXPECT_GT(f(lo), 0.0);
    EXPECT_LT(f(hi), 0.0);
    for (int k = 0; k < 200; ++k) {
        const double mid = 0.5 * (lo + hi);
        (f(mid) > 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

TEST(Em, RecoversASyntheticThreeGaussianMixture) {
    const auto sample = MixtureSample(kTruth, 4000, 12);
    const MixtureFit fit = FitGaussianMixture(sample);
    ASSERT_EQ(fit.components.size(), 3u);
    double weights = 0.0;
    for (std::size_t c = 0; c < 3; ++c) {
        SCOPED_TRACE("component " + std::to_string(c));
        EXPECT_NEAR(fit.components[c].weight, kTruth[c].weight, 0.04);
        EXPECT_NEAR(fit.components[c].mean, kTruth[c].mean, 0.25 * kTruth[c].stddev);
        EXPECT_NEAR(fit.components[c].stddev, kTruth[c].stddev, 0.2 * kTruth[c].stddev);
        weights += fit.components[c].weight;
    }
    EXPECT_NEAR(weights, 1.0, 1e-12);
    EXPECT_LE(fit.iterations, 50);
    EXPECT_TRUE(std::isfinite(fit.log_likelihood));
    // The best of several starts is at least as good as the first start alone.
    EmConfig single;
    single.restarts = 1;
    EXPECT_GE(fit.log_likelihood, FitGaussianMixture(sample, single).log_likelihood);
    // The same seed gives the same fit.
    const MixtureFit again = FitGaussianMixture(sample);
    EXPECT_EQ(again.log_likelihood, fit.log_likelihood);
    EXPECT_EQ(again.restart, fit.restart);
}

TEST(Em, ThresholdIsTheCrossingOfTheFirstTwoComponents) {
    const auto sample = MixtureSample(kTruth, 4000, 3);
    std::vector<double> with_missing = sample;
    with_missing.push_back(std::numeric_limits<double>::infinity());  // a scan without a match
    const DifferenceThreshold result = EstimateDifferenceThreshold(with_missing);
    EXPECT_EQ(result.values_used, sample.size());
    EXPECT_EQ(result.values_skipped, 1u);
    ASSERT_TRUE(result.t_d.has_value());
    const auto& c = result.fit.components;
    EXPECT_NEAR(*result.t_d, NumericCrossing(c[0], c[1]), 1e-9);
    // ... and close to the crossing of the true components.
    EXPECT_NEAR(*result.t_d, NumericCrossing(kTruth[0], kTruth[1]), 0.005);
}

TEST(Em, CrossingBetweenMeans) {
    // Equal deviations and weights: the midpoint, whatever the argument order.
    const GaussianComponent a{0.5, 1.0, 0.5};
    const GaussianComponent b{0.5, 3.0, 0.5};
    EXPECT_NEAR(*CrossingBetweenMeans(a, b), 2.0, 1e-12);
    EXPECT_NEAR(*CrossingBetweenMeans(b, a), 2.0, 1e-12);
    // Equal deviations, unequal weights: the linear equation, shifted toward the lighter one.
    const GaussianComponent heavy{0.8, 1.0, 0.5};
    const GaussianComponent light{0.2, 3.0, 0.5};
    EXPECT_NEAR(*CrossingBetweenMeans(heavy, light), 2.0 + 0.25 * std::log(4.0) / 2.0, 1e-12);
    EXPECT_NEAR(*CrossingBetweenMeans(heavy, light), NumericCrossing(heavy, light), 1e-9);
    // Unequal and nearly equal deviations: the quadratic.
    for (const double s : {0.2, 0.49, 0.4999999, 0.7, 1.5}) {
        const GaussianComponent second{0.6, 3.0, s};
        EXPECT_NEAR(*CrossingBetweenMeans(a, second), NumericCrossing(a, second), 1e-9) << s;
    }
    // One component dominating the whole interval, or equal means: no crossing.
    EXPECT_FALSE(CrossingBetweenMeans({0.001, 1.0, 0.5}, {0.999, 1.5, 2.0}).has_value());
    EXPECT_FALSE(CrossingBetweenMeans({0.5, 1.0, 0.5}, {0.5, 1.0, 0.7}).has_value());
}

TEST(Em, VarianceFloorStopsCollapse) {
    // Half the values are exactly 0 (e.g. duplicated scans): a component would collapse there.
    auto sample = MixtureSample(kTruth, 600, 4);
    sample.insert(sample.end(), 600, 0.0);
    EmConfig config;
    config.min_stddev_fraction = 0.01;
    const MixtureFit fit = FitGaussianMixture(sample, config);
    double mean = 0.0;
    for (const double x : sample) mean += x;
    mean /= static_cast<double>(sample.size());
    double squares = 0.0;
    for (const double x : sample) squares += (x - mean) * (x - mean);
    const double floor = 0.01 * std::sqrt(squares / static_cast<double>(sample.size()));
    for (const auto& c : fit.components) EXPECT_GE(c.stddev, floor * (1 - 1e-12));
    EXPECT_TRUE(std::isfinite(fit.log_likelihood));
    EXPECT_LE(fit.components[0].mean, fit.components[1].mean);
    EXPECT_LE(fit.components[1].mean, fit.components[2].mean);
}

void ExpectConfigError(void (*mutate)(EmConfig&), const std::string& field) {
    EmConfig config;
    mutate(config);
    EXPECT_TRUE(test::Contains(test::ConfigErrorOf([&] { config.Validate(); }), field));
}

TEST(Em, RejectsAbsurdConfigsAndSamples) {
    ExpectConfigError([](EmConfig& c) { c.components = 1; }, "em.components");
    ExpectConfigError([](EmConfig& c) { c.restarts = 0; }, "em.restarts");
    ExpectConfigError([](EmConfig& c) { c.max_iterations = 0; }, "em.max_iterations");
    ExpectConfigError([](EmConfig& c) { c.tolerance = -1.0; }, "em.tolerance");
    ExpectConfigError([](EmConfig& c) { c.tolerance = std::nan(""); }, "em.tolerance");
    ExpectConfigError([](EmConfig& c) { c.min_stddev_fraction = 0.0; }, "em.min_stddev_fraction");
    ExpectConfigError([](EmConfig& c) { c.min_stddev_fraction = 2.0; }, "em.min_stddev_fraction");
    const std::vector<double> two{0.1, 0.2};
    EXPECT_THROW(FitGaussianMixture(two), core::EmptyInputError);
    const std::vector<double> equal(10, 0.3);
    EXPECT_THROW(FitGaussianMixture(equal), core::Error);
    std::vector<double> with_nan{0.1, 0.2, 0.3, std::nan("")};
    EXPECT_THROW(FitGaussianMixture(with_nan), core::Error);
    EmConfig bad;
    bad.components = 1;
    EXPECT_THROW(EstimateDifferenceThreshold(MixtureSample(kTruth, 100, 5), bad),
                 core::ConfigError);
}

// A results file that gives few scans a match, or one distance to all of them (a yes/no
// detector), leaves nothing to fit: no EM threshold, not an error that stops the evaluation.
TEST(Em, NothingToFitGivesNoThreshold) {
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<std::vector<double>> samples{
        std::vector<double>(5, inf),           // no scan has a match
        {0.1, inf, 0.2, inf},                  // two values for three Gaussians
        {0.0, 0.0, inf, 0.0, 0.0, 0.0, inf}};  // one distance for every match
    for (const auto& sample : samples) {
        const DifferenceThreshold result = EstimateDifferenceThreshold(sample);
        EXPECT_FALSE(result.Fitted());
        EXPECT_FALSE(result.t_d.has_value());
        EXPECT_EQ(result.values_used, 0u);
        EXPECT_EQ(result.values_skipped,
                  static_cast<std::size_t>(std::count(sample.begin(), sample.end(), inf)));
    }
    const std::vector<double> three{0.1, 0.2, 0.9};
    EXPECT_TRUE(EstimateDifferenceThreshold(three).Fitted());
}

}  // namespace
}  // namespace lidarloop::eval

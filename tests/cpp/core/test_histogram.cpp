#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/histogram.hpp"
#include "lidarloop/core/wasserstein.hpp"
#include "test_utils.hpp"

namespace lidarloop::core {
namespace {

double Sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

HistogramConfig SmallConfig() {
    HistogramConfig config;
    config.bins = 10;
    config.height_min_m = 0.0;
    config.height_max_m = 10.0;
    config.range_min_m = 0.0;
    config.range_max_m = 10.0;
    return config;
}

TEST(Histogram, CountsHeightsIntoTheRightBuckets) {
    const PointCloud cloud = {{5, 5, 0.5f}, {-3, 1, 0.7f}, {0, 0, 3.2f}, {1, 1, 9.99f}};
    const Histogram h = ComputeHistogram(cloud, Projection::kHeight, SmallConfig());
    ASSERT_EQ(h.mass.size(), 10U);
    EXPECT_DOUBLE_EQ(h.mass[0], 0.5);
    EXPECT_DOUBLE_EQ(h.mass[3], 0.25);
    EXPECT_DOUBLE_EQ(h.mass[9], 0.25);
    EXPECT_EQ(h.points_used, 4U);
    EXPECT_EQ(h.points_skipped, 0U);
}

TEST(Histogram, CountsRangesIntoTheRightBuckets) {
    const PointCloud cloud = {{3, 4, 0}, {0, 0, 1.5f}, {0, -2, 0}};  // ranges 5, 1.5, 2
    const Histogram h = ComputeHistogram(cloud, Projection::kRange, SmallConfig());
    EXPECT_NEAR(h.mass[5], 1.0 / 3.0, 1e-15);
    EXPECT_NEAR(h.mass[1], 1.0 / 3.0, 1e-15);
    EXPECT_NEAR(h.mass[2], 1.0 / 3.0, 1e-15);
}

TEST(Histogram, UpperBoundaryBelongsToLastBucketAndLowerToFirst) {
    const PointCloud cloud = {{0, 0, 0.0f}, {0, 0, 10.0f}};
    const Histogram h = ComputeHistogram(cloud, Projection::kHeight, SmallConfig());
    EXPECT_DOUBLE_EQ(h.mass.front(), 0.5);
    EXPECT_DOUBLE_EQ(h.mass.back(), 0.5);
    EXPECT_EQ(h.points_out_of_range, 0U);
}

TEST(Histogram, ClampPutsOutOfRangeValuesIntoEndBuckets) {
    const PointCloud cloud = {{0, 0, -50.0f}, {0, 0, 50.0f}, {0, 0, 5.5f}, {0, 0, 5.6f}};
    const Histogram h = ComputeHistogram(cloud, Projection::kHeight, SmallConfig());
    EXPECT_DOUBLE_EQ(h.mass.front(), 0.25);
    EXPECT_DOUBLE_EQ(h.mass.back(), 0.25);
    EXPECT_DOUBLE_EQ(h.mass[5], 0.5);
    EXPECT_EQ(h.points_out_of_range, 2U);
    EXPECT_EQ(h.points_used, 4U);
}

TEST(Histogram, DropIgnoresOutOfRangeValuesAndStillSumsToOne) {
    HistogramConfig config = SmallConfig();
    config.out_of_range = OutOfRangePolicy::kDrop;
    const PointCloud cloud = {{0, 0, -50.0f}, {0, 0, 50.0f}, {0, 0, 5.5f}, {0, 0, 7.5f}};
    const Histogram h = ComputeHistogram(cloud, Projection::kHeight, config);
    EXPECT_DOUBLE_EQ(h.mass[5], 0.5);
    EXPECT_DOUBLE_EQ(h.mass[7], 0.5);
    EXPECT_EQ(h.points_out_of_range, 2U);
    EXPECT_EQ(h.points_used, 2U);
}

TEST(Histogram, SkipsAndCountsNonFinitePoints) {
    constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
    constexpr float kInf = std::numeric_limits<float>::infinity();
    const PointCloud cloud = {{kNan, 0, 1}, {0, kInf, 1}, {0, 0, -kInf}, {0, 0, 2.5f}};
    const Histogram h = ComputeHistogram(cloud, Projection::kHeight, SmallConfig());
    EXPECT_EQ(h.points_skipped, 3U);
    EXPECT_EQ(h.points_used, 1U);
    EXPECT_DOUBLE_EQ(h.mass[2], 1.0);
}

// Ranges are computed four points at a time and the rest one by one: a cloud longer than a block
// and not a multiple of four, with non-finite and overflowing points among the others, must give
// every point the bucket it was built for.
TEST(Histogram, RangesOfEveryPointLandInTheirBucketsWithNonFiniteOnesSkipped) {
    constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
    constexpr float kInf = std::numeric_limits<float>::infinity();
    const HistogramConfig config = SmallConfig();  // 10 buckets of 1 m over [0, 10] m
    std::mt19937 rng(31);
    std::normal_distribution<float> direction(0.0f, 1.0f);
    std::uniform_int_distribution<int> bucket_of(0, 9);
    std::uniform_real_distribution<float> offset_in_bucket(0.2f, 0.8f);  // far from the borders
    PointCloud cloud;
    std::vector<double> expected(10, 0.0);
    std::size_t non_finite = 0;
    std::size_t overflowing = 0;
    for (int i = 0; i < 1031; ++i) {
        if (i % 97 == 3) {
            cloud.push_back({i % 2 ? kNan : 1.0f, i % 2 ? 1.0f : kInf, 2.0f});
            ++non_finite;
        } else if (i % 211 == 5) {
            cloud.push_back({1e30f, 0.0f, 0.0f});  // finite, but its squared range is +inf
            ++overflowing;
            expected[9] += 1.0;
        } else {
            const int bucket = bucket_of(rng);
            const Eigen::Vector3f unit =
                Eigen::Vector3f{direction(rng), direction(rng), direction(rng)}.normalized();
            cloud.push_back(unit * (static_cast<float>(bucket) + offset_in_bucket(rng)));
            expected[static_cast<std::size_t>(bucket)] += 1.0;
        }
    }
    const Histogram h = ComputeHistogram(cloud, Projection::kRange, config);
    EXPECT_EQ(h.points_skipped, non_finite);
    EXPECT_EQ(h.points_out_of_range, overflowing);
    ASSERT_EQ(h.points_used, 1031U - non_finite);
    for (std::size_t k = 0; k < 10; ++k) {
        EXPECT_DOUBLE_EQ(h.mass[k] * static_cast<double>(h.points_used), expected[k]) << k;
    }
}

TEST(Histogram, EmptyOrUnusableScanIsAnError) {
    constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(ComputeHistogram(PointCloud{}, Projection::kHeight, SmallConfig()),
                 EmptyInputError);
    EXPECT_THROW(ComputeHistogram({{kNan, kNan, kNan}}, Projection::kRange, SmallConfig()),
                 EmptyInputError);
    HistogramConfig drop = SmallConfig();
    drop.out_of_range = OutOfRangePolicy::kDrop;
    EXPECT_THROW(ComputeHistogram({{0, 0, 99.0f}}, Projection::kHeight, drop), EmptyInputError);
}

TEST(Histogram, SensorHeightShiftsTheHistogram) {
    HistogramConfig config = SmallConfig();
    config.sensor_height_m = 2.0;  // the ground at z = -2 m becomes height 0
    const PointCloud cloud = {{1, 1, -2.0f}, {1, 1, 1.5f}};
    const Histogram h = ComputeHistogram(cloud, Projection::kHeight, config);
    EXPECT_DOUBLE_EQ(h.mass[0], 0.5);
    EXPECT_DOUBLE_EQ(h.mass[3], 0.5);
}

TEST(Histogram, SumsToOneOnRandomClouds) {
    HistogramConfig config;
    const PointCloud cloud = test::RandomCloud(5000, 7, 40.0f);
    for (auto projection : {Projection::kHeight, Projection::kRange}) {
        const Histogram h = ComputeHistogram(cloud, projection, config);
        EXPECT_NEAR(Sum(h.mass), 1.0, 1e-12);
        EXPECT_TRUE(std::all_of(h.mass.begin(), h.mass.end(), [](double m) { return m >= 0; }));
    }
}

TEST(Histogram, MatchesBruteForceBucketAssignment) {
    HistogramConfig config;
    config.bins = 37;
    const PointCloud cloud = test::RandomCloud(3000, 8, 5.0f);
    const Histogram h = ComputeHistogram(cloud, Projection::kHeight, config);
    // Reference: test every bucket's interval for every point (eq. 2), clamping outside values.
    std::vector<double> expected(37, 0.0);
    const double width = (config.height_max_m - config.height_min_m) / 37.0;
    for (const auto& p : cloud) {
        const double v = std::clamp<double>(p.z(), config.height_min_m, config.height_max_m);
        for (int k = 0; k < 37; ++k) {
            const double lo = config.height_min_m + k * width;
            if ((v >= lo && v < lo + width) || (k == 36 && v >= lo)) {
                expected[k] += 1.0 / 3000.0;
                break;
            }
        }
    }
    for (int k = 0; k < 37; ++k) EXPECT_NEAR(h.mass[k], expected[k], 1e-12) << "bucket " << k;
}

TEST(Histogram, HeightIsInvariantToYawAndPermutation) {
    PointCloud cloud = test::RandomCloud(4000, 9, 30.0f);
    HistogramConfig config;
    const Histogram reference = ComputeHistogram(cloud, Projection::kHeight, config);
    std::mt19937 rng(10);
    std::shuffle(cloud.begin(), cloud.end(), rng);
    const Eigen::Matrix3f yaw = Eigen::AngleAxisf(1.234f, Eigen::Vector3f::UnitZ()).matrix();
    for (auto& p : cloud) p = yaw * p;
    const Histogram rotated = ComputeHistogram(cloud, Projection::kHeight, config);
    EXPECT_EQ(reference.mass, rotated.mass);  // z is untouched by a yaw rotation, bit for bit
    EXPECT_EQ(WassersteinDistance(reference.mass, rotated.mass), 0.0);
}

TEST(Histogram, RangeIsInvariantToAnyRotation) {
    PointCloud cloud = test::RandomCloud(4000, 11, 30.0f);
    HistogramConfig config;
    const Histogram reference = ComputeHistogram(cloud, Projection::kRange, config);
    const Eigen::Matrix3f rotation =
        Eigen::Quaternionf(Eigen::Vector4f(0.3f, -0.5f, 0.7f, 0.4f).normalized()).matrix();
    for (auto& p : cloud) p = rotation * p;
    const Histogram rotated = ComputeHistogram(cloud, Projection::kRange, config);
    // Float rounding may move a value across a bucket border; allow a handful of points.
    EXPECT_LT(WassersteinDistance(reference.mass, rotated.mass), 5.0 / 4000.0 / 100.0 * 2);
}

TEST(Histogram, PcaHeightIsInvariantToAnyRotation) {
    // A tilted ground plane with some clutter; PCA re-finds the up vector after rotation.
    std::mt19937 rng(12);
    std::uniform_real_distribution<float> xy(-30.0f, 30.0f);
    std::normal_distribution<float> noise(0.0f, 0.02f);
    PointCloud cloud;
    for (int i = 0; i < 20000; ++i) cloud.push_back({xy(rng), xy(rng), -1.8f + noise(rng)});
    for (int i = 0; i < 500; ++i)
        cloud.push_back({xy(rng) / 10, 10.0f, 3.0f * static_cast<float>(i % 7)});
    HistogramConfig config;
    config.up_vector = UpVectorMode::kPca;
    const Histogram reference = ComputeHistogram(cloud, Projection::kHeight, config);
    const Eigen::Matrix3f tilt = (Eigen::AngleAxisf(0.8f, Eigen::Vector3f::UnitZ()) *
                                  Eigen::AngleAxisf(0.15f, Eigen::Vector3f(1, 1, 0).normalized()))
                                     .matrix();
    for (auto& p : cloud) p = tilt * p;
    const Histogram rotated = ComputeHistogram(cloud, Projection::kHeight, config);
    EXPECT_LT(WassersteinDistance(reference.mass, rotated.mass), 1e-4);
    EXPECT_NEAR(rotated.up.dot(tilt.col(2).cast<double>()), 1.0, 1e-4);
}

TEST(HistogramConfig, DefaultsAreValid) { EXPECT_NO_THROW(HistogramConfig{}.Validate()); }

TEST(HistogramConfig, RejectsAbsurdValues) {
    const auto expect_invalid = [](auto mutate, const std::string& phrase) {
        HistogramConfig config;
        mutate(config);
        EXPECT_TRUE(test::Contains(test::ConfigErrorOf([&] { config.Validate(); }), phrase));
    };
    expect_invalid([](HistogramConfig& c) { c.bins = 0; }, "bins");
    expect_invalid([](HistogramConfig& c) { c.bins = -5; }, "bins");
    expect_invalid([](HistogramConfig& c) { c.bins = 2'000'000; }, "bins");
    expect_invalid([](HistogramConfig& c) { c.height_min_m = c.height_max_m; }, "height_min_m");
    expect_invalid([](HistogramConfig& c) { c.range_max_m = -1; }, "range_min_m");
    expect_invalid([](HistogramConfig& c) { c.range_min_m = -1; }, "range_min_m");
    expect_invalid([](HistogramConfig& c) { c.height_max_m = NAN; }, "height_max_m");
    expect_invalid([](HistogramConfig& c) { c.sensor_height_m = INFINITY; }, "sensor_height_m");
    expect_invalid([](HistogramConfig& c) { c.sensor_height_m = 1e300; }, "sensor_height_m");
    // A span that overflows would put every value in the first bucket.
    expect_invalid(
        [](HistogramConfig& c) {
            c.height_min_m = -1e308;
            c.height_max_m = 1e308;
        },
        "must be a finite span");
}

TEST(HistogramConfig, InvalidConfigIsRejectedByCompute) {
    HistogramConfig config;
    config.bins = 0;
    EXPECT_THROW(ComputeHistogram({{0, 0, 0}}, Projection::kHeight, config), ConfigError);
}

}  // namespace
}  // namespace lidarloop::core

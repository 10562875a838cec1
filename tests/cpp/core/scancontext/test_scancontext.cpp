// Scan Context (Kim & Kim, IROS 2018) against a brute-force reading of the paper's equations,
// written here independently of the kernels: bins, ring key, column-shift distance and yaw.
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/scancontext/scancontext.hpp"
#include "lidarloop/core/scancontext/scancontext_distance.hpp"

namespace lidarloop::core {
namespace {

// Section III-A: ring from the planar range, sector from atan2, value the largest z + h.
std::vector<float> BruteForceBins(const PointCloud& cloud, const ScanContextConfig& c) {
    std::vector<float> bins(static_cast<std::size_t>(c.rings * c.sectors), 0.0f);
    for (const Eigen::Vector3f& p : cloud) {
        if (!p.allFinite()) continue;
        const double range_m = std::hypot(double{p.x()}, double{p.y()});
        if (range_m >= c.max_range_m) continue;
        double azimuth_rad = std::atan2(double{p.y()}, double{p.x()});
        if (azimuth_rad < 0.0) azimuth_rad += 2.0 * std::numbers::pi;
        const int ring = static_cast<int>(std::floor(range_m / (c.max_range_m / c.rings)));
        const int sector =
            static_cast<int>(std::floor(azimuth_rad / (2.0 * std::numbers::pi / c.sectors)));
        float& bin = bins[static_cast<std::size_t>(ring * c.sectors + sector)];
        bin = std::max(bin, p.z() + static_cast<float>(c.sensor_height_m));
    }
    return bins;
}

// Eq. 6: the share of non-zero bins per ring.
std::vector<float> BruteForceRingKey(const std::vector<float>& bins, int rings, int sectors) {
    std::vector<float> key;
    for (int i = 0; i < rings; ++i) {
        int occupied = 0;
        for (int j = 0; j < sectors; ++j) occupied += bins[i * sectors + j] != 0.0f ? 1 : 0;
        key.push_back(static_cast<float>(occupied) / static_cast<float>(sectors));
    }
    return key;
}

struct BruteMatch {
    double distance = 1.0;
    int shift = 0;
};

// Eq. 5 at shift n: the mean of 1 - cos over the columns occupied in either, a column occupied in
// one only counting 1 (1 when both are empty).
double BruteForceAtShift(const std::vector<float>& q, const std::vector<float>& c, int rings,
                         int sectors, int n) {
    double sum = 0.0;
    int columns = 0;
    for (int j = 0; j < sectors; ++j) {
        const int jc = (j + n) % sectors;
        double dot = 0.0, qq = 0.0, cc = 0.0;
        for (int i = 0; i < rings; ++i) {
            const double a = q[i * sectors + j], b = c[i * sectors + jc];
            dot += a * b, qq += a * a, cc += b * b;
        }
        if (qq == 0.0 && cc == 0.0) continue;
        sum += qq == 0.0 || cc == 0.0 ? 1.0 : 1.0 - dot / std::sqrt(qq * cc);
        ++columns;
    }
    return columns > 0 ? sum / columns : 1.0;
}

// Eq. 6: the minimum over the shifts.
BruteMatch BruteForceDistance(const std::vector<float>& q, const std::vector<float>& c, int rings,
                              int sectors) {
    BruteMatch best;
    for (int n = 0; n < sectors; ++n) {
        const double d = BruteForceAtShift(q, c, rings, sectors, n);
        if (d < best.distance) best = {d, n};
    }
    return best;
}

// Points spread over the disc up to 100 m, heights from -3 to 6 m; some exactly on the axis.
PointCloud RandomScan(unsigned seed, std::size_t points) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> xy(-100.0f, 100.0f), z(-3.0f, 6.0f);
    PointCloud cloud;
    for (std::size_t i = 0; i < points; ++i) cloud.push_back({xy(rng), xy(rng), z(rng)});
    cloud.emplace_back(0.0f, 0.0f, 1.0f);
    cloud.emplace_back(5.0f, 0.0f, 1.0f);  // on the border of sectors 59 and 0
    return cloud;
}

// A scene in polar coordinates whose points keep clear of the sector borders, so that turning it
// by whole sectors moves every point into the bin k sectors on.
PointCloud PolarScene(unsigned seed, int sectors) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> inside(0.2, 0.8), range(1.0, 79.0), z(-1.0, 8.0);
    std::uniform_int_distribution<int> sector(0, sectors - 1);
    PointCloud cloud;
    for (int i = 0; i < 3000; ++i) {
        const int whole_sectors = sector(rng);
        const double azimuth_rad = (whole_sectors + inside(rng)) * 2.0 * std::numbers::pi / sectors;
        const double r = range(rng);
        cloud.emplace_back(static_cast<float>(r * std::cos(azimuth_rad)),
                           static_cast<float>(r * std::sin(azimuth_rad)),
                           static_cast<float>(z(rng)));
    }
    return cloud;
}

PointCloud TurnedBy(const PointCloud& cloud, double yaw_rad) {
    const Eigen::Matrix3f R =
        Eigen::AngleAxisf(static_cast<float>(yaw_rad), Eigen::Vector3f::UnitZ()).toRotationMatrix();
    PointCloud turned;
    for (const Eigen::Vector3f& p : cloud) turned.push_back(R * p);
    return turned;
}

std::string ErrorOf(const ScanContextConfig& config) {
    try {
        config.Validate();
    } catch (const ConfigError& e) {
        return e.what();
    }
    return "no error";
}

TEST(ScanContext, BinsAndRingKeyAreThePapersEquations) {
    const ScanContextConfig config;
    for (unsigned seed : {1U, 2U, 3U}) {
        const PointCloud cloud = RandomScan(seed, 4000);
        const ScanContext sc = ComputeScanContext(cloud, config);
        ASSERT_EQ(sc.rings, 20);
        ASSERT_EQ(sc.sectors, 60);
        EXPECT_EQ(sc.bins, BruteForceBins(cloud, config)) << seed;
        EXPECT_EQ(sc.ring_key, BruteForceRingKey(sc.bins, 20, 60)) << seed;
    }
}

TEST(ScanContext, OtherShapesAndHeightsBinTheSameWay) {
    ScanContextConfig config;
    config.rings = 7;
    config.sectors = 13;
    config.max_range_m = 50.0;
    config.sensor_height_m = 0.5;
    const PointCloud cloud = RandomScan(4, 3000);
    const ScanContext sc = ComputeScanContext(cloud, config);
    EXPECT_EQ(sc.bins, BruteForceBins(cloud, config));
    EXPECT_EQ(sc.ring_key, BruteForceRingKey(sc.bins, 7, 13));
}

TEST(ScanContext, DistanceIsTheMinimumOverShiftsOfTheMeanColumnCosineDistance) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> height(0.0f, 5.0f), u(0.0f, 1.0f);
    for (int trial = 0; trial < 50; ++trial) {
        const int rings = 1 + trial % 20, sectors = 6 + 7 * (trial % 9);
        // Sparse random matrices: empty bins, some empty columns.
        const auto random_bins = [&] {
            std::vector<float> bins(static_cast<std::size_t>(rings * sectors), 0.0f);
            for (int j = 0; j < sectors; ++j) {
                if (u(rng) < 0.3f) continue;
                for (int i = 0; i < rings; ++i)
                    if (u(rng) < 0.6f) bins[i * sectors + j] = height(rng);
            }
            return bins;
        };
        const std::vector<float> q = random_bins(), c = random_bins();
        const ScanContextMatch match = CompareScanContexts(ScanContextColumns(q, rings, sectors),
                                                           ScanContextColumns(c, rings, sectors));
        const BruteMatch expected = BruteForceDistance(q, c, rings, sectors);
        EXPECT_NEAR(match.distance, expected.distance, 1e-5) << trial;
        // The shift found gives that distance (another shift may tie to float rounding).
        EXPECT_NEAR(BruteForceAtShift(q, c, rings, sectors, match.shift), match.distance, 1e-5);
    }
}

TEST(ScanContext, AScanTurnedByKSectorsMatchesAtShiftKWithItsYaw) {
    const ScanContextConfig config;
    const PointCloud scene = PolarScene(6, config.sectors);
    const ScanContext original = ComputeScanContext(scene, config);
    for (int k : {0, 1, 7, 29, 30, 31, 45, 59}) {
        const double sector_rad = 2.0 * std::numbers::pi / config.sectors;
        const ScanContext turned = ComputeScanContext(TurnedBy(scene, k * sector_rad), config);
        EXPECT_EQ(turned.ring_key, original.ring_key) << k;  // the ring key ignores yaw
        const ScanContextMatch match = CompareScanContexts(original, turned);
        EXPECT_EQ(match.shift, k);
        EXPECT_EQ(match.distance, 0.0) << k;
        const double expected_yaw_rad = k <= 30 ? k * sector_rad : (k - 60) * sector_rad;
        EXPECT_NEAR(match.yaw_rad, expected_yaw_rad, 1e-9) << k;
        // The other way round the shift is -k.
        EXPECT_EQ(CompareScanContexts(turned, original).shift, (60 - k) % 60) << k;
    }
}

TEST(ScanContext, EqualDescriptorsAreAtZeroAndTheDistanceIsSymmetric) {
    const ScanContextConfig config;
    const ScanContext a = ComputeScanContext(RandomScan(7, 3000), config);
    const ScanContext b = ComputeScanContext(RandomScan(8, 3000), config);
    EXPECT_EQ(CompareScanContexts(a, a).distance, 0.0);
    EXPECT_EQ(CompareScanContexts(a, a).shift, 0);
    const double ab = CompareScanContexts(a, b).distance;
    EXPECT_GT(ab, 0.01);
    EXPECT_LE(ab, 1.0);
    EXPECT_NEAR(CompareScanContexts(b, a).distance, ab, 1e-6);
}

TEST(ScanContext, NoCommonColumnIsDistanceOne) {
    std::vector<float> q(2 * 6, 0.0f), c(2 * 6, 0.0f);
    q[0] = 1.0f;  // column 0
    const ScanContextMatch none =
        CompareScanContexts(ScanContextColumns(q, 2, 6), ScanContextColumns(c, 2, 6));
    EXPECT_EQ(none.distance, 1.0);
    EXPECT_EQ(none.shift, 0);
}

// A column occupied in one descriptor only counts as cos 0; a column empty in both is skipped.
TEST(ScanContext, AColumnOccupiedInOneOnlyCountsAsDistanceOne) {
    std::vector<float> q(2 * 6, 0.0f), c(2 * 6, 0.0f);
    q[0] = c[0] = 1.0f;          // column 0, ring 0 in both
    q[6 + 1] = c[6 + 1] = 2.0f;  // column 1, ring 1 in both
    c[3] = 4.0f;                 // column 3, candidate only
    const ScanContextMatch match =
        CompareScanContexts(ScanContextColumns(q, 2, 6), ScanContextColumns(c, 2, 6));
    EXPECT_EQ(match.shift, 0);
    EXPECT_NEAR(match.distance, 1.0 / 3.0, 1e-7);  // (0 + 0 + 1) / 3 columns
}

TEST(ScanContext, NonFinitePointsAreSkippedAndFarPointsDropped) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const PointCloud cloud = {{nan, 1.0f, 1.0f},   {1.0f, inf, 1.0f},    {1.0f, 1.0f, -inf},
                              {80.0f, 0.0f, 1.0f}, {0.0f, -95.0f, 1.0f}, {79.99f, 0.1f, 3.0f},
                              {2.0f, 0.1f, -5.0f}};
    const ScanContext sc = ComputeScanContext(cloud, {});
    EXPECT_EQ(sc.points_skipped, 3U);
    EXPECT_EQ(sc.points_out_of_range, 2U);  // 80 m itself is beyond [0, L_max)
    EXPECT_EQ(sc.points_used, 2U);
    EXPECT_FLOAT_EQ(sc.at(19, 0), 5.0f);  // 3 m + the 2 m sensor height
    EXPECT_EQ(sc.at(0, 0), 0.0f);         // 5 m below the sensor: below the ground, reads 0
    EXPECT_FLOAT_EQ(sc.ring_key[19], 1.0f / 60.0f);
    EXPECT_EQ(sc.ring_key[0], 0.0f);
}

TEST(ScanContext, AScanWithNothingUsableIsAnEmptyInputError) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(ComputeScanContext(PointCloud{}, {}), EmptyInputError);
    EXPECT_THROW(ComputeScanContext(PointCloud{{nan, nan, nan}}, {}), EmptyInputError);
    EXPECT_THROW(ComputeScanContext(PointCloud{{100.0f, 0.0f, 0.0f}}, {}), EmptyInputError);
}

TEST(ScanContext, AbsurdConfigsAreClearErrors) {
    const auto with = [](auto change) {
        ScanContextConfig c;
        change(c);
        return ErrorOf(c);
    };
    EXPECT_EQ(ErrorOf({}), "no error");
    EXPECT_EQ(with([](auto& c) { c.rings = 0; }), "scancontext.rings must be in [1, 200], got 0");
    EXPECT_EQ(with([](auto& c) { c.rings = 100000; }),
              "scancontext.rings must be in [1, 200], got 100000");
    EXPECT_EQ(with([](auto& c) { c.sectors = 3; }),
              "scancontext.sectors must be in [6, 720], got 3");
    EXPECT_EQ(with([](auto& c) { c.max_range_m = 0.0; }),
              "scancontext.max_range_m must be in [0.1, 10000], got 0");
    EXPECT_EQ(with([](auto& c) { c.max_range_m = std::nan(""); }).find("max_range_m"), 12U);
    EXPECT_NE(with([](auto& c) { c.max_range_m = HUGE_VAL; }), "no error");
    EXPECT_NE(with([](auto& c) { c.sensor_height_m = std::nan(""); }), "no error");
    EXPECT_EQ(with([](auto& c) { c.ring_key_candidates = -1; }),
              "scancontext.ring_key_candidates must be in [0, 1000000], got -1");
    EXPECT_THROW(ComputeScanContext(PointCloud{{1.0f, 1.0f, 1.0f}}, ScanContextConfig{0}),
                 ConfigError);
}

TEST(ScanContext, DescriptorsOfDifferentShapesDoNotCompare) {
    ScanContextConfig small;
    small.sectors = 30;
    const PointCloud cloud = RandomScan(9, 500);
    EXPECT_THROW(
        CompareScanContexts(ComputeScanContext(cloud, {}), ComputeScanContext(cloud, small)),
        ConfigError);
}

}  // namespace
}  // namespace lidarloop::core

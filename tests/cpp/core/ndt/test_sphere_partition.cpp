#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/ndt/sphere_partition.hpp"
#include "test_utils.hpp"

namespace lidarloop::core {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Uniform on the whole sphere (normalised Gaussian vectors), so uniform over lines as well; this
// sampler knows nothing of the z-uniformity the partition is built on.
Eigen::Vector3d RandomDirection(std::mt19937& rng) {
    std::normal_distribution<double> normal(0.0, 1.0);
    Eigen::Vector3d d;
    do {
        d = {normal(rng), normal(rng), normal(rng)};
    } while (d.norm() < 1e-6);
    return d.normalized();
}

Eigen::Vector3d Upper(const Eigen::Vector3d& d) { return d.z() < 0.0 ? Eigen::Vector3d(-d) : d; }

// Membership by the published bounds, written independently of RegionOf: colatitude from atan2,
// longitude in [0, 2*pi) compared with the region's interval, which may pass 2*pi.
bool Contains(const SphereRegion& region, const Eigen::Vector3d& upper) {
    const double colatitude = std::atan2(std::hypot(upper.x(), upper.y()), upper.z());
    if (colatitude < region.colatitude_min || colatitude > region.colatitude_max) return false;
    double longitude = std::atan2(upper.y(), upper.x());
    if (longitude < 0.0) longitude += kTwoPi;
    const auto inside = [&](double l) {
        return l >= region.longitude_min && l <= region.longitude_max;
    };
    return inside(longitude) || inside(longitude + kTwoPi);
}

// Magnusson eq. (2) as written: the point-to-line distance ||e - (e.c)c|| for unit e, minimised
// by scanning every line. Also returns the gap to the second-nearest line.
int BruteForceNearestLine(const Eigen::Vector3d& direction,
                          const std::vector<Eigen::Vector3d>& centres, double& min_distance,
                          double& gap) {
    const Eigen::Vector3d e = direction.normalized();
    int best = -1;
    min_distance = std::numeric_limits<double>::infinity();
    double second = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < centres.size(); ++j) {
        const double distance = (e - e.dot(centres[j]) * centres[j]).norm();
        if (distance < min_distance) {
            second = min_distance;
            min_distance = distance;
            best = static_cast<int>(j);
        } else if (distance < second) {
            second = distance;
        }
    }
    gap = second - min_distance;
    return best;
}

double LineDistance(const Eigen::Vector3d& direction, const Eigen::Vector3d& centre) {
    const Eigen::Vector3d e = direction.normalized();
    return (e - e.dot(centre) * centre).norm();
}

TEST(HalfSpherePartition, RegionsHaveEqualAreaByMonteCarlo) {
    // Each region's share of 2 million uniform lines is Binomial(N, 1/n)/N; allow 5 standard
    // deviations (about 2.5 % of 1/n for n = 50).
    constexpr int kSamples = 2'000'000;
    for (int n : {1, 2, 3, 9, 16, 50}) {
        const HalfSpherePartition partition(n);
        std::mt19937 rng(100 + static_cast<unsigned>(n));
        std::vector<int> counts(static_cast<std::size_t>(n), 0);
        for (int s = 0; s < kSamples; ++s) ++counts[partition.RegionOf(RandomDirection(rng))];
        const double p = 1.0 / n;
        const double tolerance = 5.0 * std::sqrt(p * (1.0 - p) / kSamples);
        for (int j = 0; j < n; ++j) {
            EXPECT_NEAR(counts[j] / static_cast<double>(kSamples), p, tolerance)
                << "n = " << n << ", region " << j;
        }
    }
}

TEST(HalfSpherePartition, ZonesTileTheHalfSphereInEqualAreasForEveryValidCount) {
    // Exhaustive over the valid domain (n² work in all: under the sanitizers, which look for
    // memory errors the small counts reach as well, only up to 1000). The area of a region is
    // (cos colatitude_min - cos colatitude_max) * (longitude_max - longitude_min).
    const int max_count = test::kSanitizedBuild ? 1000 : 10000;
    for (int n = 1; n <= max_count; ++n) {
        const HalfSpherePartition partition(n);
        ASSERT_EQ(partition.size(), n);
        ASSERT_EQ(static_cast<int>(partition.regions().size()), n);
        const double expected_area = kTwoPi / n;
        for (const SphereRegion& r : partition.regions()) {
            const double area = (std::cos(r.colatitude_min) - std::cos(r.colatitude_max)) *
                                (r.longitude_max - r.longitude_min);
            ASSERT_NEAR(area, expected_area, 1e-9 * expected_area)
                << "n = " << n << ", zone " << r.zone;
        }
        const auto& colatitudes = partition.zone_colatitudes();
        const auto& counts = partition.zone_region_counts();
        ASSERT_EQ(colatitudes.size(), counts.size() + 1) << n;
        ASSERT_EQ(colatitudes.front(), 0.0) << n;
        ASSERT_EQ(colatitudes.back(), std::numbers::pi / 2.0) << n;
        for (std::size_t k = 0; k + 1 < colatitudes.size(); ++k) {
            ASSERT_LT(colatitudes[k], colatitudes[k + 1]) << n;
        }
        ASSERT_EQ(counts.front(), 1) << n;
        for (int c : counts) ASSERT_GE(c, 1) << n;
        ASSERT_EQ(std::accumulate(counts.begin(), counts.end(), 0), n);
        // Regions come zone by zone, and the sectors of a zone tile the full turn.
        std::size_t index = 0;
        for (std::size_t zone = 0; zone < counts.size(); ++zone) {
            const double width = kTwoPi / counts[zone];
            const double first_start = partition.regions()[index].longitude_min;
            for (int j = 0; j < counts[zone]; ++j, ++index) {
                const SphereRegion& r = partition.regions()[index];
                ASSERT_EQ(r.zone, static_cast<int>(zone));
                ASSERT_EQ(r.colatitude_min, colatitudes[zone]);
                ASSERT_EQ(r.colatitude_max, colatitudes[zone + 1]);
                ASSERT_GE(r.longitude_min, 0.0);
                ASSERT_LT(r.longitude_min, kTwoPi);
                ASSERT_NEAR(r.longitude_max - r.longitude_min, width, 1e-12);
                const double start = std::fmod(first_start + j * width, kTwoPi);
                const double wrapped = std::remainder(r.longitude_min - start, kTwoPi);
                ASSERT_NEAR(wrapped, 0.0, 1e-9) << "n = " << n << ", zone " << zone;
            }
        }
    }
}

TEST(HalfSpherePartition, EverySampleLiesInExactlyOneRegion) {
    std::mt19937 rng(7);
    for (int n : {1, 2, 3, 9, 16, 50, 64, 257}) {
        const HalfSpherePartition partition(n);
        for (int s = 0; s < 20000; ++s) {
            const Eigen::Vector3d d = RandomDirection(rng);
            const int region = partition.RegionOf(d);
            ASSERT_GE(region, 0);
            ASSERT_LT(region, n);
            int containing = 0;
            int found = -1;
            for (int j = 0; j < n; ++j) {
                if (Contains(partition.regions()[j], Upper(d))) {
                    ++containing;
                    found = j;
                }
            }
            ASSERT_EQ(containing, 1) << "n = " << n << ", sample " << s;
            ASSERT_EQ(found, region) << "n = " << n << ", sample " << s;
        }
    }
}

TEST(HalfSpherePartition, LineAndItsOppositeShareARegion) {
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> angle(0.0, kTwoPi);
    for (int n : {1, 2, 3, 9, 16, 50, 1000}) {
        const HalfSpherePartition partition(n);
        for (int s = 0; s < 5000; ++s) {
            const Eigen::Vector3d d = RandomDirection(rng);
            EXPECT_EQ(partition.RegionOf(d), partition.RegionOf(-d));
            EXPECT_EQ(partition.NearestLine(d), partition.NearestLine(-d));
            // Any non-zero length, including extreme scales.
            EXPECT_EQ(partition.RegionOf(3.5 * d), partition.RegionOf(d));
            EXPECT_EQ(partition.RegionOf(1e-300 * d), partition.RegionOf(d));
            EXPECT_EQ(partition.RegionOf(-1e300 * d), partition.RegionOf(d));
            // Exactly on the equator both d and -d are upper points; the one with y > 0 decides.
            const double phi = angle(rng);
            const Eigen::Vector3d e(std::cos(phi), std::sin(phi), 0.0);
            const int region = partition.RegionOf(e);
            EXPECT_EQ(region, partition.RegionOf(-e));
            EXPECT_TRUE(
                Contains(partition.regions()[region], e.y() > 0.0 ? e : Eigen::Vector3d(-e)))
                << "n = " << n << ", phi = " << phi;
        }
        // Axes, signed zeros and the pole.
        const std::vector<Eigen::Vector3d> axes = {{1, 0, 0},    {0, 1, 0},       {0, 0, 1},
                                                   {1, -0.0, 0}, {-0.0, 1, -0.0}, {2, 0, -0.0}};
        for (const Eigen::Vector3d& a : axes) {
            EXPECT_EQ(partition.RegionOf(a), partition.RegionOf(-a)) << a.transpose();
        }
        EXPECT_EQ(partition.RegionOf(Eigen::Vector3d(0, 0, -7)), 0);
        EXPECT_EQ(partition.NearestLine(Eigen::Vector3d(0, 0, -7)), 0);
    }
}

TEST(HalfSpherePartition, EachCentreLiesInsideItsOwnRegion) {
    for (int n : {1, 2, 3, 4, 5, 9, 16, 50, 64, 100, 1000, 10000}) {
        const HalfSpherePartition partition(n);
        ASSERT_EQ(partition.centres().size(), static_cast<std::size_t>(n));
        for (int j = 0; j < n; ++j) {
            const Eigen::Vector3d& c = partition.centres()[j];
            EXPECT_NEAR(c.norm(), 1.0, 1e-15);
            EXPECT_GT(c.z(), 0.0);
            EXPECT_TRUE(Contains(partition.regions()[j], c)) << "n = " << n << ", region " << j;
            EXPECT_EQ(partition.RegionOf(c), j) << "n = " << n;
            EXPECT_EQ(partition.RegionOf(-c), j) << "n = " << n;
            EXPECT_EQ(partition.NearestLine(c), j) << "n = " << n;
        }
        EXPECT_EQ(partition.centres()[0], Eigen::Vector3d::UnitZ());
    }
}

TEST(HalfSpherePartition, NearestLineMatchesBruteForceDistance) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> length(0.01, 100.0);
    for (int n : {1, 2, 3, 9, 16, 50, 64}) {
        const HalfSpherePartition partition(n);
        for (int s = 0; s < 20000; ++s) {
            const double length_m = length(rng);
            const Eigen::Vector3d d = length_m * RandomDirection(rng);
            double min_distance = 0.0;
            double gap = 0.0;
            const int expected = BruteForceNearestLine(d, partition.centres(), min_distance, gap);
            const int actual = partition.NearestLine(d);
            ASSERT_GE(actual, 0);
            ASSERT_LT(actual, n);
            EXPECT_LE(LineDistance(d, partition.centres()[actual]), min_distance + 1e-12);
            if (gap > 1e-9) {
                EXPECT_EQ(actual, expected) << "n = " << n << ", sample " << s;
            }
        }
    }
}

TEST(HalfSpherePartition, NearestLineBreaksTiesTowardsTheLowestIndex) {
    // A zero direction is equally far from every line, and NaN compares false everywhere: both
    // keep the first index rather than reading past the centres.
    for (int n : {1, 9, 64}) {
        const HalfSpherePartition partition(n);
        EXPECT_EQ(partition.NearestLine(Eigen::Vector3d::Zero()), 0);
        EXPECT_EQ(partition.NearestLine(Eigen::Vector3d::Constant(std::nan(""))), 0);
    }
}

TEST(HalfSpherePartition, AdjacentCollarsAreStaggered) {
    // Leopardi's collar offset: centre longitudes of collars with t and b sectors differ by
    // multiples of gcd(t, b)/(t b) turns plus the offset, which puts them half a step apart, the
    // largest possible minimum separation.
    for (int n : {16, 27, 50, 64, 100, 1000}) {
        const HalfSpherePartition partition(n);
        const auto& counts = partition.zone_region_counts();
        int first = 1;
        for (std::size_t zone = 1; zone + 1 < counts.size(); ++zone) {
            const int t = counts[zone];
            const int b = counts[zone + 1];
            double min_separation = 1.0;
            for (int j = 0; j < t; ++j) {
                for (int k = 0; k < b; ++k) {
                    const Eigen::Vector3d& top = partition.centres()[first + j];
                    const Eigen::Vector3d& bottom = partition.centres()[first + t + k];
                    const double turns =
                        (std::atan2(top.y(), top.x()) - std::atan2(bottom.y(), bottom.x())) /
                        kTwoPi;
                    min_separation = std::min(min_separation, std::abs(std::remainder(turns, 1.0)));
                }
            }
            EXPECT_NEAR(min_separation, std::gcd(t, b) / (2.0 * t * b), 1e-12)
                << "n = " << n << ", zones " << zone << " and " << zone + 1;
            first += t;
        }
    }
    // n = 50, collars of 6 then 11 sectors: offset (1/11 - 1/6)/2 + 1/132 = -1/33 turn.
    const HalfSpherePartition fifty(50);
    EXPECT_NEAR(fifty.regions()[1 + 6].longitude_min, kTwoPi * 32.0 / 33.0, 1e-12);
}

TEST(HalfSpherePartition, NineRegionsAreACapAndOneCollarOfEight) {
    // By hand, n = 9 (Magnusson's p): region area V = 2*pi/9. Polar cap: 1 - cos(theta_c) = 1/9,
    // theta_c = acos(8/9) = 0.47588 rad (27.27 deg). Ideal collar angle sqrt(V) = 0.83554; the
    // span pi/2 - theta_c = 1.09492 holds 1.3104 of them, which rounds to 1 collar, whose ideal
    // region count (2*pi - V)/V = 8 needs no rounding. Centres: the pole, then 8 points at
    // colatitude (theta_c + pi/2)/2 = 1.02334 rad and longitudes (j + 1/2) * 45 deg (the first
    // collar has no offset).
    const HalfSpherePartition partition(9);
    EXPECT_EQ(partition.size(), 9);
    EXPECT_EQ(partition.zone_region_counts(), (std::vector<int>{1, 8}));
    ASSERT_EQ(partition.zone_colatitudes().size(), 3U);
    EXPECT_EQ(partition.zone_colatitudes()[0], 0.0);
    EXPECT_NEAR(partition.zone_colatitudes()[1], std::acos(8.0 / 9.0), 1e-14);
    EXPECT_EQ(partition.zone_colatitudes()[2], std::numbers::pi / 2.0);
    EXPECT_EQ(partition.centres()[0], Eigen::Vector3d::UnitZ());
    const double colatitude = (std::acos(8.0 / 9.0) + std::numbers::pi / 2.0) / 2.0;
    for (int j = 0; j < 8; ++j) {
        const double longitude = (j + 0.5) * std::numbers::pi / 4.0;
        const Eigen::Vector3d expected(std::sin(colatitude) * std::cos(longitude),
                                       std::sin(colatitude) * std::sin(longitude),
                                       std::cos(colatitude));
        EXPECT_LT((partition.centres()[1 + j] - expected).norm(), 1e-14) << j;
        EXPECT_NEAR(partition.regions()[1 + j].longitude_min, j * std::numbers::pi / 4.0, 1e-14)
            << j;
    }
}

TEST(HalfSpherePartition, SmallCountsHaveTheExpectedZones) {
    // n = 1: the whole half sphere. n = 2: the cap of area pi (theta_c = 60 deg) and a ring down
    // to the equator. n = 16: theta_c = 0.35542, 1.9395 ideal collars -> 2; fitting angle
    // 0.60773; ideal counts 5.8645 and 9.1355; rounding with the running discrepancy gives 6
    // (a = -0.1355) and round(9.1355 - 0.1355) = 9.
    const HalfSpherePartition one(1);
    EXPECT_EQ(one.zone_region_counts(), (std::vector<int>{1}));
    EXPECT_EQ(one.zone_colatitudes(), (std::vector<double>{0.0, std::numbers::pi / 2.0}));
    EXPECT_EQ(one.RegionOf(Eigen::Vector3d(1, 2, -3)), 0);
    const HalfSpherePartition two(2);
    EXPECT_EQ(two.zone_region_counts(), (std::vector<int>{1, 1}));
    EXPECT_NEAR(two.zone_colatitudes()[1], std::numbers::pi / 3.0, 1e-15);
    EXPECT_EQ(HalfSpherePartition(16).zone_region_counts(), (std::vector<int>{1, 6, 9}));
    EXPECT_EQ(HalfSpherePartition(50).zone_region_counts(), (std::vector<int>{1, 6, 11, 15, 17}));
    // n = 27, where the running discrepancy matters: 3 collars with ideal counts 5.4471, 9.2337
    // and 11.3191. round(5.4471) = 5 leaves a = 0.4471; round(9.2337 + 0.4471) = 10 leaves
    // a = -0.3192; round(11.3191 - 0.3192) = 11. Rounding each alone would give 5, 9, 11 (sum 26).
    EXPECT_EQ(HalfSpherePartition(27).zone_region_counts(), (std::vector<int>{1, 5, 10, 11}));
}

TEST(HalfSpherePartition, RejectsInvalidCountsAndDirections) {
    EXPECT_THROW(HalfSpherePartition(0), ConfigError);
    EXPECT_THROW(HalfSpherePartition(-1), ConfigError);
    EXPECT_THROW(HalfSpherePartition(10001), ConfigError);
    EXPECT_NO_THROW(HalfSpherePartition(1));
    EXPECT_NO_THROW(HalfSpherePartition(10000));
    const std::string message = test::ConfigErrorOf([] { HalfSpherePartition bad(10001); });
    EXPECT_TRUE(test::Contains(message, "[1, 10000]"));
    EXPECT_TRUE(test::Contains(message, "10001"));
    const HalfSpherePartition partition(9);
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_THROW(partition.RegionOf(Eigen::Vector3d::Zero()), Error);
    EXPECT_THROW(partition.RegionOf(Eigen::Vector3d(std::nan(""), 0, 1)), Error);
    EXPECT_THROW(partition.RegionOf(Eigen::Vector3d(inf, 0, 1)), Error);
}

}  // namespace
}  // namespace lidarloop::core

#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/kd_tree.hpp"

namespace lidarloop::core {
namespace {

// Clustered points with exact duplicates and a coarse grid (many equal distances), seeded.
std::vector<Eigen::Vector3d> TestPoints(unsigned seed, std::size_t count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> wide(-50.0, 50.0);
    std::normal_distribution<double> cluster(0.0, 2.0);
    std::uniform_int_distribution<int> grid(-5, 5);
    std::vector<Eigen::Vector3d> points;
    for (std::size_t i = 0; i < count; ++i) {
        switch (i % 4) {
            case 0:
                points.push_back({wide(rng), wide(rng), wide(rng)});
                break;
            case 1:
                points.push_back({cluster(rng), cluster(rng), 0.1 * cluster(rng)});
                break;
            case 2:
                points.push_back(Eigen::Vector3i{grid(rng), grid(rng), grid(rng)}.cast<double>());
                break;
            default: {
                const Eigen::Vector3d duplicate =
                    points[static_cast<std::size_t>(grid(rng) + 5) % points.size()];
                points.push_back(duplicate);
                break;
            }
        }
    }
    return points;
}

std::vector<std::size_t> BruteRadius(const std::vector<Eigen::Vector3d>& points,
                                     const Eigen::Vector3d& q, double radius_m) {
    std::vector<std::size_t> found;
    for (std::size_t i = 0; i < points.size(); ++i) {
        if ((points[i] - q).squaredNorm() < radius_m * radius_m) found.push_back(i);
    }
    return found;
}

template <typename Accept>
std::optional<Neighbor> BruteNearest(const std::vector<Eigen::Vector3d>& points,
                                     const Eigen::Vector3d& q, Accept accept) {
    std::optional<Neighbor> best;
    double best_squared = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (!accept(i)) continue;
        const double squared = (points[i] - q).squaredNorm();
        if (!best || squared < best_squared) {
            best = Neighbor{i, std::sqrt(squared)};
            best_squared = squared;
        }
    }
    return best;
}

TEST(KdTree3, RadiusSearchEqualsBruteForce) {
    const auto points = TestPoints(7, 1500);
    const KdTree3 tree(points);
    ASSERT_EQ(tree.size(), points.size());
    std::mt19937 rng(11);
    std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
    for (const double radius : {0.0, 0.5, 1.0, 2.0, 3.0, 10.0, 40.0}) {
        for (int k = 0; k < 60; ++k) {
            // Queries on data points and on grid points: many points exactly at the radius.
            const Eigen::Vector3d q =
                k % 2 == 0 ? points[pick(rng)] : Eigen::Vector3d(k % 5, -(k % 3), 1.0);
            EXPECT_EQ(tree.RadiusSearch(q, radius), BruteRadius(points, q, radius))
                << "radius " << radius << " query " << k;
        }
    }
}

TEST(KdTree3, NearestEqualsBruteForceWithTiesToSmallerIndex) {
    const auto points = TestPoints(3, 1200);
    const KdTree3 tree(points);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> coordinate(-60.0, 60.0);
    for (int k = 0; k < 300; ++k) {
        const Eigen::Vector3d q =
            k % 3 == 0 ? points[static_cast<std::size_t>(k)]
                       : Eigen::Vector3d{coordinate(rng), coordinate(rng), coordinate(rng)};
        const auto expected = BruteNearest(points, q, [](std::size_t) { return true; });
        const auto actual = tree.Nearest(q);
        ASSERT_TRUE(actual.has_value());
        EXPECT_EQ(actual->index, expected->index) << "query " << k;
        EXPECT_EQ(actual->distance_m, expected->distance_m);
    }
}

TEST(KdTree3, NearestIfEqualsBruteForce) {
    const auto points = TestPoints(9, 1000);
    const KdTree3 tree(points);
    for (std::size_t qi = 0; qi < points.size(); qi += 7) {
        // Like a minimum gap: skip indices close to the query's own.
        const auto accept = [qi](std::size_t j) { return (j > qi ? j - qi : qi - j) > 40; };
        const auto expected = BruteNearest(points, points[qi], accept);
        const auto actual = tree.NearestIf(points[qi], accept);
        ASSERT_EQ(actual.has_value(), expected.has_value());
        EXPECT_EQ(actual->index, expected->index) << "query " << qi;
        EXPECT_EQ(actual->distance_m, expected->distance_m);
    }
    EXPECT_FALSE(tree.NearestIf(points[0], [](std::size_t) { return false; }).has_value());
}

TEST(KdTree3, EmptyTreeAndInfiniteRadius) {
    const KdTree3 empty({});
    EXPECT_TRUE(empty.RadiusSearch(Eigen::Vector3d::Zero(), 5.0).empty());
    EXPECT_FALSE(empty.Nearest(Eigen::Vector3d::Zero()).has_value());
    const auto points = TestPoints(1, 50);
    const KdTree3 tree(points);
    EXPECT_EQ(
        tree.RadiusSearch(Eigen::Vector3d::Zero(), std::numeric_limits<double>::infinity()).size(),
        points.size());
}

TEST(KdTree3, RejectsBadInput) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(KdTree3({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(nan, 0, 0)}), Error);
    const KdTree3 tree({Eigen::Vector3d::Zero()});
    EXPECT_THROW(tree.RadiusSearch(Eigen::Vector3d::Zero(), -1.0), Error);
    EXPECT_THROW(tree.RadiusSearch(Eigen::Vector3d::Zero(), nan), Error);
}

TEST(KdTree3, MovedTreeStillAnswers) {
    const auto points = TestPoints(2, 100);
    KdTree3 first(points);
    const KdTree3 second(std::move(first));
    EXPECT_EQ(second.RadiusSearch(points[0], 3.0), BruteRadius(points, points[0], 3.0));
}

}  // namespace
}  // namespace lidarloop::core

// The voxel grid against a plain reference (a std::map of cells), its exact coarsening, and the
// map of placed scans built on it: placement, the size cap, bad configurations and poses.
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/point_map.hpp"
#include "lidarloop/core/voxel_grid.hpp"

namespace lidarloop::core {
namespace {

struct Reference {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double value = 0.0;
    std::uint64_t count = 0;
    std::size_t first = 0;  // index of the first point: the order of the voxels
};

// Brute force: every point's cell by floor(p / v), summed in a std::map.
std::vector<Voxel> BruteVoxels(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<double>& values, double voxel_m) {
    std::map<std::tuple<long, long, long>, Reference> cells;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const Eigen::Vector3d& p = points[i];
        const auto key = std::make_tuple(std::lround(std::floor(p.x() / voxel_m)),
                                         std::lround(std::floor(p.y() / voxel_m)),
                                         std::lround(std::floor(p.z() / voxel_m)));
        auto [it, inserted] = cells.try_emplace(key);
        if (inserted) it->second.first = i;
        it->second.sum += p;
        it->second.value += values[i];
        ++it->second.count;
    }
    std::vector<std::pair<std::size_t, Voxel>> ordered;
    for (const auto& [key, r] : cells) {
        const auto n = static_cast<double>(r.count);
        ordered.push_back({r.first, {r.sum / n, r.value / n, r.count}});
    }
    std::sort(ordered.begin(), ordered.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<Voxel> voxels;
    for (const auto& entry : ordered) voxels.push_back(entry.second);
    return voxels;
}

// Clustered and spread points on both sides of every axis, some exactly on cell borders.
std::vector<Eigen::Vector3d> TestPoints(unsigned seed, std::size_t count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> wide(-30.0, 30.0);
    std::normal_distribution<double> cluster(0.0, 0.5);
    std::uniform_int_distribution<int> border(-20, 20);
    std::vector<Eigen::Vector3d> points;
    for (std::size_t i = 0; i < count; ++i) {
        if (i % 3 == 0) {
            points.push_back({wide(rng), wide(rng), wide(rng)});
        } else if (i % 3 == 1) {
            points.push_back({cluster(rng), cluster(rng), cluster(rng)});
        } else {
            points.push_back({0.25 * border(rng), 0.25 * border(rng), 0.25 * border(rng)});
        }
    }
    return points;
}

void ExpectSameVoxels(const std::vector<Voxel>& actual, const std::vector<Voxel>& expected,
                      double tolerance) {
    ASSERT_EQ(actual.size(), expected.size());
    for (std::size_t v = 0; v < actual.size(); ++v) {
        ASSERT_EQ(actual[v].count, expected[v].count) << "voxel " << v;
        EXPECT_LE((actual[v].centroid - expected[v].centroid).norm(), tolerance) << "voxel " << v;
        EXPECT_NEAR(actual[v].mean_value, expected[v].mean_value, tolerance) << "voxel " << v;
    }
}

TEST(VoxelGrid, MatchesBruteForce) {
    for (const double voxel_m : {0.25, 0.37, 2.0}) {
        const std::vector<Eigen::Vector3d> points = TestPoints(7, 20000);
        std::vector<double> values;
        for (std::size_t i = 0; i < points.size(); ++i)
            values.push_back(0.1 * static_cast<double>(i % 97));
        VoxelGrid grid(voxel_m);
        for (std::size_t i = 0; i < points.size(); ++i) ASSERT_TRUE(grid.Add(points[i], values[i]));
        const std::vector<Voxel> expected = BruteVoxels(points, values, voxel_m);
        EXPECT_GT(expected.size(), 1000u);
        // The same sums in the same order: equal to the last bit.
        ExpectSameVoxels(grid.Voxels(), expected, 0.0);
        EXPECT_EQ(grid.size(), expected.size());
    }
}

// The batched, prefetching path is the same grid, also with points it skips and a table that
// grows within a batch.
TEST(VoxelGrid, AddAllEqualsAddingOneByOne) {
    std::vector<Eigen::Vector3d> points = TestPoints(5, 5003);
    points[17].x() = std::numeric_limits<double>::quiet_NaN();
    points[4000].z() = 1e300;
    VoxelGrid one(0.3), all(0.3);
    std::size_t added = 0;
    for (const auto& p : points) added += one.Add(p, 2.5) ? 1 : 0;
    EXPECT_EQ(all.AddAll(points, 2.5), added);
    EXPECT_EQ(added, points.size() - 2);
    ExpectSameVoxels(all.Voxels(), one.Voxels(), 0.0);
}

// The table grows from 64 buckets through many rehashes without losing a voxel.
TEST(VoxelGrid, GrowsWithoutLosingVoxels) {
    VoxelGrid grid(1.0);
    for (int x = -60; x < 60; ++x) {
        for (int y = -60; y < 60; ++y) grid.Add(Eigen::Vector3d(x + 0.5, y + 0.5, 0.5));
    }
    ASSERT_EQ(grid.size(), 120u * 120u);
    for (int x = -60; x < 60; ++x) grid.Add(Eigen::Vector3d(x + 0.1, 0.2, 0.3));  // known cells
    EXPECT_EQ(grid.size(), 120u * 120u);
    EXPECT_GT(grid.MemoryBytes(), 120u * 120u * 64u);
}

TEST(VoxelGrid, CoarsenEqualsAddingAtTheDoubleEdge) {
    const std::vector<Eigen::Vector3d> points = TestPoints(11, 20000);
    std::vector<double> values(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) values[i] = static_cast<double>(i);
    VoxelGrid fine(0.1);
    for (std::size_t i = 0; i < points.size(); ++i) fine.Add(points[i], values[i]);
    for (const double edge : {0.2, 0.4, 0.8}) {
        fine.Coarsen();
        EXPECT_DOUBLE_EQ(fine.voxel_m(), edge);
        // Sums regrouped: equal up to rounding.
        ExpectSameVoxels(fine.Voxels(), BruteVoxels(points, values, edge), 1e-9);
    }
}

TEST(VoxelGrid, SkipsPointsItCannotPlace) {
    VoxelGrid grid(0.5);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_FALSE(grid.Add(Eigen::Vector3d(nan, 0, 0)));
    EXPECT_FALSE(grid.Add(Eigen::Vector3d(0, inf, 0)));
    EXPECT_FALSE(grid.Add(Eigen::Vector3d(0, 0, 1e300)));  // no int64 cell holds it
    EXPECT_TRUE(grid.Add(Eigen::Vector3d(-1e8, 1e8, 0)));  // the pose readers' bound
    EXPECT_EQ(grid.size(), 1u);
}

TEST(VoxelGrid, BadEdgesAreConfigErrors) {
    for (const double edge : {0.0, -0.2, std::numeric_limits<double>::quiet_NaN(),
                              std::numeric_limits<double>::infinity()}) {
        EXPECT_THROW(VoxelGrid{edge}, ConfigError) << edge;
    }
}

TEST(PointMap, PlacesScansWithTheirPoses) {
    MapConfig config;
    config.voxel_m = 1.0;
    PointMap map(config);
    const PointCloud scan{{0.5f, 0.5f, 0.5f}, {std::nanf(""), 0.0f, 0.0f}};
    Transform T_world_scan = Transform::Identity();
    T_world_scan.translate(Eigen::Vector3d(10.0, 0.0, 0.0));
    T_world_scan.rotate(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
    map.AddScan(scan, T_world_scan, 5.0);
    map.AddScan(scan, Transform::Identity(), 7.0);
    const MapCloud cloud = map.Cloud();
    ASSERT_EQ(cloud.points.size(), 2u);
    EXPECT_TRUE(cloud.points[0].position.isApprox(Eigen::Vector3d(9.5, 0.5, 0.5), 1e-6));
    EXPECT_DOUBLE_EQ(cloud.points[0].time_s, 5.0);
    EXPECT_DOUBLE_EQ(cloud.points[1].time_s, 7.0);
    EXPECT_EQ(cloud.scans, 2u);
    EXPECT_EQ(cloud.input_points, 2u);  // the NaN point is skipped
    EXPECT_DOUBLE_EQ(cloud.first_time_s, 5.0);
    EXPECT_DOUBLE_EQ(cloud.last_time_s, 7.0);
}

// A map that would exceed max_points gets a coarser voxel, the one adding every point at that
// edge gives, and so stays bounded.
TEST(PointMap, KeepsToItsSizeBound) {
    MapConfig config;
    config.voxel_m = 0.05;
    config.max_points = 1000;
    PointMap map(config);
    const std::vector<Eigen::Vector3d> points = TestPoints(3, 30000);
    PointCloud scan;
    for (const auto& p : points) scan.push_back(p.cast<float>());
    map.AddScan(scan, Transform::Identity(), 0.0);
    const MapCloud cloud = map.Cloud();
    EXPECT_LE(cloud.points.size(), 1000u);
    EXPECT_GT(cloud.voxel_m, 0.05);
    EXPECT_DOUBLE_EQ(std::log2(cloud.voxel_m / 0.05), std::round(std::log2(cloud.voxel_m / 0.05)));
    VoxelGrid direct(cloud.voxel_m);
    for (const auto& p : scan) direct.Add(p.cast<double>());
    EXPECT_EQ(cloud.points.size(), direct.size());
    VoxelGrid finer(cloud.voxel_m / 2);
    for (const auto& p : scan) finer.Add(p.cast<double>());
    EXPECT_GT(finer.size(), 1000u);  // not coarser than needed
}

TEST(PointMap, BadConfigsAndPosesAreErrors) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const double voxel_m : {0.0, -1.0, nan, 0.001, 1000.0}) {
        MapConfig config;
        config.voxel_m = voxel_m;
        try {
            PointMap map(config);
            FAIL() << "voxel_m " << voxel_m << " accepted";
        } catch (const ConfigError& e) {
            EXPECT_NE(std::string(e.what()).find("map.voxel_m must be in [0.01, 100] m"),
                      std::string::npos)
                << e.what();
        }
    }
    MapConfig few;
    few.max_points = 10;
    EXPECT_THROW(PointMap{few}, ConfigError);
    PointMap map(MapConfig{});
    Transform bad = Transform::Identity();
    bad.translation().x() = nan;
    EXPECT_THROW(map.AddScan(PointCloud{{1, 2, 3}}, bad, 0.0), Error);
    EXPECT_THROW(map.AddScan(PointCloud{{1, 2, 3}}, Transform::Identity(), nan), Error);
    EXPECT_EQ(map.size(), 0u);
}

}  // namespace
}  // namespace lidarloop::core

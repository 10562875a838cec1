#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/sim/scene.hpp"
#include "lidarloop/sim/world.hpp"
#include "sim/sim_test_utils.hpp"
#include "test_utils.hpp"

namespace lidarloop::sim {
namespace {

TEST(World, RayHitsKnownBoxAndPlaneAtAnalyticRange) {
    // Ground z = 0, a 4 m x 6 m x 3 m box whose near face is 10 m ahead of a sensor at 1.73 m.
    const World world(Terrain(), 0.0, {Box{{12.0, 0.0, 1.5}, {2.0, 3.0, 1.5}, 0.0}}, 2.0);
    const Eigen::Vector3d sensor(0.0, 0.0, 1.73);
    EXPECT_NEAR(world.CastRay(MakeRay(sensor, {1, 0, 0}), 100.0), 10.0, 1e-9);
    const double up = 5.0 * std::numbers::pi / 180.0;  // hits the face at z = 1.73 + 10 tan 5
    EXPECT_NEAR(world.CastRay(MakeRay(sensor, {std::cos(up), 0, std::sin(up)}), 100.0),
                10.0 / std::cos(up), 1e-9);
    const double down = 15.0 * std::numbers::pi / 180.0;  // ground at 6.46 m, before the box
    EXPECT_NEAR(world.CastRay(MakeRay(sensor, {std::cos(down), 0, -std::sin(down)}), 100.0),
                1.73 / std::sin(down), 1e-9);
    EXPECT_NEAR(world.CastRay(MakeRay(sensor, {0, 1, -1}), 100.0), 1.73 * std::sqrt(2.0), 1e-9);
    EXPECT_EQ(world.CastRay(MakeRay(sensor, {-1, 0, 0.1}), 100.0), kNoHit);  // sky
    EXPECT_EQ(world.CastRay(MakeRay(sensor, {1, 0, 0}), 9.0), kNoHit);       // beyond range
}

TEST(World, CeilingClosesTheWorldAbove) {
    const World world(Terrain(), 3.0, {}, 1.0);
    const double up = 30.0 * std::numbers::pi / 180.0;
    EXPECT_NEAR(world.CastRay(MakeRay({0, 0, 1}, {std::cos(up), 0, std::sin(up)}), 50.0), 4.0,
                1e-9);
    EXPECT_TRUE(world.IsFree({0, 0, 1}, 0.5));
    EXPECT_FALSE(world.IsFree({0, 0, 3.5}, 0.5));
    EXPECT_FALSE(world.IsFree({0, 0, -0.1}, 0.5));
}

TEST(World, RejectsBadGridCell) {
    EXPECT_THROW(World(Terrain(), 0.0, {}, 0.0), core::ConfigError);
    EXPECT_THROW(World(Terrain(), -1.0, {}, 1.0), core::ConfigError);
}

// The grid must give exactly what testing every object gives.
class GridParity : public ::testing::TestWithParam<SceneType> {};

TEST_P(GridParity, GridMatchesBruteForce) {
    const World world = GenerateWorld(GetParam(), 7, {-1, 1, -1, 1});
    const SceneLayout layout = LayoutOf(GetParam());
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> along(-0.5 * layout.block_pitch_m,
                                                 0.5 * layout.block_pitch_m);
    std::uniform_real_distribution<double> lane(-layout.road_half_width_m + 0.5,
                                                layout.road_half_width_m - 0.5);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    int hits = 0;
    for (int k = 0; k < 800; ++k) {
        // Sensors on the streets (x or y on a street line), rays in every direction.
        Eigen::Vector3d origin = k % 2 == 0 ? Eigen::Vector3d{along(rng), lane(rng), 0.0}
                                            : Eigen::Vector3d{lane(rng), along(rng), 0.0};
        origin.z() = world.ground().Height(origin.x(), origin.y()) + 1.5;
        const Ray ray = MakeRay(origin, {unit(rng), unit(rng), 0.4 * unit(rng)});
        const double grid = world.CastRay(ray, 120.0);
        const double brute = world.CastRayBruteForce(ray, 120.0);
        if (brute == kNoHit) {
            EXPECT_EQ(grid, kNoHit) << "ray " << k;
        } else {
            EXPECT_NEAR(grid, brute, 1e-9) << "ray " << k;
            ++hits;
        }
    }
    EXPECT_GT(hits, 250);
}

INSTANTIATE_TEST_SUITE_P(AllScenes, GridParity,
                         ::testing::Values(SceneType::kUrban, SceneType::kRural, SceneType::kMine,
                                           SceneType::kIndoor),
                         [](const auto& test_info) { return ToString(test_info.param); });

using ObjectKey = std::tuple<std::size_t, double, double, double, double, double, double>;

std::vector<ObjectKey> Keys(const World& world) {
    std::vector<ObjectKey> keys;
    for (const auto& object : world.objects()) {
        const Aabb b = Bounds(object);
        keys.emplace_back(object.index(), b.min_m.x(), b.min_m.y(), b.min_m.z(), b.max_m.x(),
                          b.max_m.y(), b.max_m.z());
    }
    return keys;
}

TEST(Scene, SameSeedSameWorldOtherSeedOtherWorld) {
    for (const SceneType type :
         {SceneType::kUrban, SceneType::kRural, SceneType::kMine, SceneType::kIndoor}) {
        const NodeRange nodes{0, 3, 0, 2};
        const auto a = Keys(GenerateWorld(type, 11, nodes));
        EXPECT_GT(a.size(), 20u) << ToString(type);
        EXPECT_EQ(a, Keys(GenerateWorld(type, 11, nodes))) << ToString(type);
        EXPECT_NE(a, Keys(GenerateWorld(type, 12, nodes))) << ToString(type);
    }
    EXPECT_NE(GenerateTerrain(SceneType::kUrban, 1).Height(10, 20),
              GenerateTerrain(SceneType::kUrban, 2).Height(10, 20));
    EXPECT_EQ(GenerateTerrain(SceneType::kIndoor, 1).max_slope(), 0.0);
}

TEST(Scene, LargerRangeKeepsTheContentOfTheSmallerOne) {
    const auto small = Keys(GenerateWorld(SceneType::kUrban, 5, {0, 2, 0, 2}));
    const auto large = Keys(GenerateWorld(SceneType::kUrban, 5, {-1, 3, -1, 2}));
    const std::set<ObjectKey> in_large(large.begin(), large.end());
    for (const auto& key : small) EXPECT_TRUE(in_large.count(key));
}

TEST(Scene, TerrainStaysWithinItsBounds) {
    for (const SceneType type : {SceneType::kUrban, SceneType::kRural, SceneType::kMine}) {
        const SceneLayout layout = LayoutOf(type);
        const Terrain terrain = GenerateTerrain(type, 3);
        EXPECT_LE(terrain.max_slope(), layout.terrain_max_slope + 1e-12);
        EXPECT_LE(terrain.max_height_m(), layout.terrain_amplitude_m + 1e-12);
        EXPECT_GT(terrain.max_slope(), 0.0);
    }
}

TEST(Scene, NamesRoundTripAndUnknownNamesAreErrors) {
    for (const SceneType type :
         {SceneType::kUrban, SceneType::kRural, SceneType::kMine, SceneType::kIndoor}) {
        EXPECT_EQ(ParseSceneType(ToString(type)), type);
    }
    EXPECT_EQ(test::ConfigErrorOf([] { ParseSceneType("moon"); }),
              "unknown scene 'moon' (valid: urban, rural, mine, indoor)");
    EXPECT_THROW(GenerateWorld(SceneType::kUrban, 1, {0, 0, 0, 3}), core::ConfigError);
}

}  // namespace
}  // namespace lidarloop::sim

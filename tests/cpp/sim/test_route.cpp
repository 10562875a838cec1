#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/sim/route.hpp"
#include "lidarloop/sim/simulator.hpp"
#include "test_utils.hpp"

namespace lidarloop::sim {
namespace {

constexpr SceneType kScenes[] = {SceneType::kUrban, SceneType::kRural, SceneType::kMine,
                                 SceneType::kIndoor};
constexpr RouteType kRoutes[] = {RouteType::kUTurn, RouteType::kFigureEight, RouteType::kGrid};

// Enough scans for one and a half laps of the route at the mean spacing.
SimulationConfig LapConfig(SceneType scene, RouteType route) {
    SimulationConfig config;
    config.scene = scene;
    config.route.type = route;
    config.route.uturn_blocks = 2;
    config.sensor.model = SensorModel::kVlp16;
    const RoutePath path(RouteLegs(route, 2), LayoutOf(scene));
    config.scans = static_cast<std::size_t>(1.5 * path.lap_length_m() / 1.5) + 1;
    return config;
}

TEST(Route, LegsAreClosedLapsOfAdjacentNodes) {
    for (const RouteType route : kRoutes) {
        const auto legs = RouteLegs(route, 3);
        ASSERT_FALSE(legs.empty());
        EXPECT_EQ(legs.back().to, legs.front().from) << ToString(route);
        EXPECT_NO_THROW(RoutePath(legs, LayoutOf(SceneType::kUrban))) << ToString(route);
        EXPECT_EQ(ParseRouteType(ToString(route)), route);
    }
    EXPECT_EQ(RouteLegs(RouteType::kUTurn, 3).size(), 12u);
    EXPECT_THROW(ParseRouteType("spiral"), core::ConfigError);
    EXPECT_EQ(test::ConfigErrorOf([] { ParseRouteType("spiral"); }),
              "unknown route 'spiral' (valid: uturn, figure8, grid)");
    const SceneLayout layout = LayoutOf(SceneType::kUrban);
    EXPECT_THROW(RoutePath({{{0, 0}, {2, 0}, 0}, {{2, 0}, {0, 0}, 0}}, layout), core::ConfigError);
    EXPECT_THROW(RoutePath({{{0, 0}, {1, 0}, 0}, {{1, 0}, {1, 1}, 0}}, layout), core::ConfigError);
    EXPECT_THROW(RoutePath({{{0, 0}, {1, 0}, 2}, {{1, 0}, {0, 0}, 2}}, layout), core::ConfigError);
}

TEST(Route, PathIsContinuousAndClosed) {
    for (const SceneType scene : kScenes) {
        for (const RouteType route : kRoutes) {
            const RoutePath path(RouteLegs(route, 2), LayoutOf(scene));
            const double step = 0.05;
            RoutePoint previous = path.At(0.0);
            for (double s = step; s <= path.lap_length_m() + 1e-9; s += step) {
                const RoutePoint point = path.At(s);
                ASSERT_LE((point.position_m - previous.position_m).norm(), step + 1e-6)
                    << ToString(scene) << " " << ToString(route) << " at " << s;
                previous = point;
            }
            EXPECT_LT((path.At(path.lap_length_m()).position_m - path.At(0).position_m).norm(),
                      1e-6);
        }
    }
}

TEST(Route, SpacingVariesSmoothlyWithinItsBounds) {
    const SpacingProfile profile(1.0, 2.0, 9);
    double smallest = 1e9;
    double largest = 0.0;
    for (std::size_t i = 0; i < 5000; ++i) {
        const double step = profile.ArcLength(i + 1) - profile.ArcLength(i);
        ASSERT_GE(step, 1.0 - 1e-9);
        ASSERT_LE(step, 2.0 + 1e-9);
        if (i > 0) {
            const double previous = profile.ArcLength(i) - profile.ArcLength(i - 1);
            ASSERT_LT(std::abs(step - previous), 0.1) << "speed jumps at scan " << i;
        }
        smallest = std::min(smallest, step);
        largest = std::max(largest, step);
    }
    EXPECT_LT(smallest, 1.2);  // the speed really varies
    EXPECT_GT(largest, 1.8);
    EXPECT_EQ(profile.ArcLength(0), 0.0);
}

// Every route keeps the vehicle on free ground: the sensor and the body (0.5 m up) clear of
// every object by the vehicle's radius, under the ceiling, along the whole lap.
TEST(Route, EveryRouteStaysInFreeSpace) {
    for (const SceneType scene : kScenes) {
        for (const RouteType route : kRoutes) {
            SimulationConfig config = LapConfig(scene, route);
            config.scans = 2;
            const Simulator simulator(config);
            const World& world = simulator.world();
            const double radius = simulator.layout().vehicle_radius_m;
            const RoutePath& path = simulator.route();
            for (double s = 0.0; s < path.lap_length_m(); s += 0.25) {
                const Eigen::Vector2d p = path.At(s).position_m;
                const double ground = world.ground().Height(p.x(), p.y());
                for (const double height : {0.5, simulator.sensor().mount_height_m}) {
                    ASSERT_TRUE(world.IsFree({p.x(), p.y(), ground + height}, radius))
                        << ToString(scene) << " " << ToString(route) << " at s = " << s << " ("
                        << p.transpose() << ") height " << height;
                }
            }
        }
    }
}

// Revisits by construction: some scan comes back within 3 m of a scan at least 30 before it.
TEST(Route, EveryRouteRevisitsPlaces) {
    for (const SceneType scene : kScenes) {
        for (const RouteType route : kRoutes) {
            const Simulator simulator(LapConfig(scene, route));
            EXPECT_GT(CountRevisitedScans(simulator, 30, 3.0), 10u)
                << ToString(scene) << " " << ToString(route);
        }
    }
}

struct PairKinds {
    std::size_t opposite = 0;     // within 4.5 m, heading differs by > 150 degrees
    std::size_t lane_offset = 0;  // same heading, 2.5-4.5 m to the side
    std::size_t same_place = 0;   // same heading, within 1.6 m
};

PairKinds ClassifyRevisits(const Simulator& simulator) {
    PairKinds kinds;
    std::vector<core::Transform> poses;
    for (std::size_t i = 0; i < simulator.size(); ++i) {
        poses.push_back(simulator.GroundTruthPose(i).T_world_sensor);
    }
    for (std::size_t i = 0; i < poses.size(); ++i) {
        for (std::size_t j = i + 30; j < poses.size(); ++j) {
            const Eigen::Vector3d d = poses[j].translation() - poses[i].translation();
            if (d.head<2>().norm() > 4.5) continue;
            const Eigen::Vector3d fi = poses[i].linear().col(0);
            const double cos_angle = fi.dot(poses[j].linear().col(0));
            const double side = std::abs(poses[i].linear().col(1).dot(d));
            if (cos_angle < -0.87) ++kinds.opposite;
            if (cos_angle > 0.99 && side > 2.5) ++kinds.lane_offset;
            if (cos_angle > 0.99 && d.norm() < 1.6) ++kinds.same_place;
        }
    }
    return kinds;
}

TEST(Route, GridHasOppositeAndLaneOffsetRevisits) {
    const PairKinds kinds =
        ClassifyRevisits(Simulator(LapConfig(SceneType::kUrban, RouteType::kGrid)));
    EXPECT_GT(kinds.opposite, 20u);
    EXPECT_GT(kinds.lane_offset, 20u);
    EXPECT_GT(kinds.same_place, 20u);
}

TEST(Route, DemoSequenceHasEveryKindOfRevisit) {
    const PairKinds kinds = ClassifyRevisits(Simulator(DemoConfig()));
    EXPECT_GT(kinds.opposite, 20u);
    EXPECT_GT(kinds.lane_offset, 10u);
    EXPECT_GT(kinds.same_place, 5u);
}

TEST(Route, UTurnComesHomeOnTheOppositeLane) {
    SimulationConfig config = LapConfig(SceneType::kUrban, RouteType::kUTurn);
    config.route.uturn_blocks = 0;  // chosen from the scans: one out-and-back
    config.scans = 200;
    const Simulator simulator(config);
    EXPECT_EQ(simulator.config().route.uturn_blocks, 2);  // 200 x 1.5 m / (2 x 70 m)
    const PairKinds kinds = ClassifyRevisits(simulator);
    EXPECT_GT(kinds.opposite, 50u);
}

}  // namespace
}  // namespace lidarloop::sim

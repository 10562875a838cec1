#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "lidarloop/sim/shapes.hpp"
#include "lidarloop/sim/terrain.hpp"
#include "sim/sim_test_utils.hpp"

namespace lidarloop::sim {
namespace {

TEST(Shapes, BoxFaceHitAtAnalyticRange) {
    const Box box{{10.0, 0.0, 0.0}, {1.0, 2.0, 3.0}, 0.0};
    EXPECT_NEAR(Intersect(MakeRay({0, 0, 0}, {1, 0, 0}), box), 9.0, 1e-12);
    // Oblique: enters the face x = 9 at y = 9 * tan(10 deg) < 2.
    const double angle = 10.0 * std::numbers::pi / 180.0;
    EXPECT_NEAR(Intersect(MakeRay({0, 0, 0}, {std::cos(angle), std::sin(angle), 0}), box),
                9.0 / std::cos(angle), 1e-12);
    EXPECT_EQ(Intersect(MakeRay({0, 0, 0}, {-1, 0, 0}), box), kNoHit);  // behind
    EXPECT_EQ(Intersect(MakeRay({0, 0, 5}, {1, 0, 0}), box), kNoHit);   // above
    // From inside, the exit.
    EXPECT_NEAR(Intersect(MakeRay({10, 0, 0}, {0, 1, 0}), box), 2.0, 1e-12);
}

TEST(Shapes, TurnedBoxHitsItsCorner) {
    const Box box{{10.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, std::numbers::pi / 4.0};
    EXPECT_NEAR(Intersect(MakeRay({0, 0, 0}, {1, 0, 0}), box), 10.0 - std::sqrt(2.0), 1e-12);
    // Just past the corner's side: the turned box's extent in y is sqrt(2).
    EXPECT_NE(Intersect(MakeRay({0, 1.40, 0}, {1, 0, 0}), box), kNoHit);
    EXPECT_EQ(Intersect(MakeRay({0, 1.42, 0}, {1, 0, 0}), box), kNoHit);
}

TEST(Shapes, CylinderSideAndCap) {
    const Cylinder pole{{10.0, 0.0}, 0.5, 0.0, 4.0};
    EXPECT_NEAR(Intersect(MakeRay({0, 0, 1}, {1, 0, 0}), pole), 9.5, 1e-12);
    EXPECT_NEAR(Intersect(MakeRay({10, 0.2, 10}, {0, 0, -1}), pole), 6.0, 1e-12);  // top cap
    EXPECT_EQ(Intersect(MakeRay({0, 0, 5}, {1, 0, 0}), pole), kNoHit);
    EXPECT_EQ(Intersect(MakeRay({0, 0.6, 1}, {1, 0, 0}), pole), kNoHit);
}

TEST(Shapes, ConeRadiusShrinksWithHeight) {
    const Cone cone{{10.0, 0.0}, 2.0, 0.0, 8.0};  // radius 2 - z / 4
    for (const double z : {0.5, 2.0, 4.0, 7.0}) {
        EXPECT_NEAR(Intersect(MakeRay({0, 0, z}, {1, 0, 0}), cone), 10.0 - (2.0 - z / 4.0), 1e-9)
            << "z = " << z;
    }
    EXPECT_EQ(Intersect(MakeRay({0, 0, 8.5}, {1, 0, 0}), cone), kNoHit);
    EXPECT_NEAR(Intersect(MakeRay({10, 1.0, -5}, {0, 0, 1}), cone), 5.0, 1e-12);  // base disk
}

TEST(Shapes, EllipsoidAlongItsAxes) {
    const Ellipsoid crown{{10.0, 0.0, 3.0}, {2.0, 1.0, 0.5}};
    EXPECT_NEAR(Intersect(MakeRay({0, 0, 3}, {1, 0, 0}), crown), 8.0, 1e-12);
    EXPECT_NEAR(Intersect(MakeRay({10, -5, 3}, {0, 1, 0}), crown), 4.0, 1e-12);
    EXPECT_NEAR(Intersect(MakeRay({10, 0, 10}, {0, 0, -1}), crown), 6.5, 1e-12);
    EXPECT_EQ(Intersect(MakeRay({0, 0, 3.6}, {1, 0, 0}), crown), kNoHit);
}

TEST(Shapes, ContainsAndBounds) {
    const Shape box = Box{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, std::numbers::pi / 2.0};
    EXPECT_TRUE(Contains(box, {0.0, 1.9, 0.0}));
    EXPECT_FALSE(Contains(box, {1.5, 0.0, 0.0}));
    EXPECT_TRUE(Contains(box, {1.5, 0.0, 0.0}, 0.6));
    const Aabb bounds = Bounds(box);
    EXPECT_NEAR(bounds.max_m.x(), 1.0, 1e-12);
    EXPECT_NEAR(bounds.max_m.y(), 2.0, 1e-12);
    EXPECT_TRUE(Contains(Cone{{0, 0}, 2.0, 0.0, 4.0}, {0.9, 0.0, 2.0}));
    EXPECT_FALSE(Contains(Cone{{0, 0}, 2.0, 0.0, 4.0}, {1.1, 0.0, 2.0}));
    EXPECT_TRUE(Contains(Ellipsoid{{0, 0, 0}, {2, 1, 1}}, {1.9, 0.0, 0.0}));
    EXPECT_FALSE(Contains(Ellipsoid{{0, 0, 0}, {2, 1, 1}}, {0.0, 1.1, 0.0}));
}

TEST(Terrain, FlatGroundAndCeilingAtAnalyticRange) {
    const Terrain flat;
    const double down = 30.0 * std::numbers::pi / 180.0;
    const Ray ray = MakeRay({0, 0, 1.73}, {std::cos(down), 0, -std::sin(down)});
    EXPECT_NEAR(flat.Intersect(ray, 0.0, false, 100.0), 1.73 / std::sin(down), 1e-9);
    EXPECT_EQ(flat.Intersect(ray, 0.0, false, 3.0), kNoHit);  // beyond the range limit
    const Ray up = MakeRay({0, 0, 1.0}, {std::cos(down), 0, std::sin(down)});
    EXPECT_NEAR(flat.Intersect(up, 3.0, true, 100.0), 2.0 / std::sin(down), 1e-9);
    EXPECT_EQ(flat.Intersect(up, 0.0, false, 100.0), kNoHit);
}

TEST(Terrain, SlopedGroundHitIsTheFirstCrossing) {
    const Terrain hills({{2.0, {2 * std::numbers::pi / 200.0, 0.0}, 0.3},
                         {1.0, {0.0, 2 * std::numbers::pi / 150.0}, 1.1}});
    EXPECT_LE(hills.max_slope(), 0.11);
    for (int k = 0; k < 200; ++k) {
        const double azimuth = k * 0.0314;
        const double down = (0.5 + 0.1 * (k % 40)) * std::numbers::pi / 180.0;
        const Eigen::Vector3d origin(3.0 * k, -2.0 * k, hills.Height(3.0 * k, -2.0 * k) + 1.73);
        const Ray ray = MakeRay(origin, {std::cos(azimuth) * std::cos(down),
                                         std::sin(azimuth) * std::cos(down), -std::sin(down)});
        const double t = hills.Intersect(ray, 0.0, false, 500.0);
        if (t == kNoHit) continue;
        const Eigen::Vector3d p = ray.origin + t * ray.direction;
        EXPECT_NEAR(p.z(), hills.Height(p.x(), p.y()), 1e-6) << "ray " << k;
        for (double s = 0.0; s < t - 0.05; s += 0.05) {  // nothing crossed before
            const Eigen::Vector3d q = ray.origin + s * ray.direction;
            ASSERT_GT(q.z(), hills.Height(q.x(), q.y())) << "ray " << k << " at " << s;
        }
    }
}

}  // namespace
}  // namespace lidarloop::sim

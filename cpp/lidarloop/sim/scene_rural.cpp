// Rural blocks: open fields, farmyards with houses, barns and silos, forest patches and
// orchards, stone walls; roads with utility poles, tree rows, delineator posts and signs.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "lidarloop/core/angles.hpp"
#include "lidarloop/sim/detail/scene_builder.hpp"

namespace lidarloop::sim::detail {
namespace {

Eigen::Vector2d RandomPoint(const Rect& r, Random& rng) {
    return {rng.Uniform(r.x0, r.x1), rng.Uniform(r.y0, r.y1)};
}

// A random sub-rectangle of `r` with sides in [min_side, max_side] (clipped to r).
Rect RandomPatch(const Rect& r, double min_side, double max_side, Random& rng) {
    const double w = std::min(r.Width(), rng.Uniform(min_side, max_side));
    const double h = std::min(r.Height(), rng.Uniform(min_side, max_side));
    const double x0 = rng.Uniform(r.x0, r.x1 - w);
    const double y0 = rng.Uniform(r.y0, r.y1 - h);
    return {x0, y0, x0 + w, y0 + h};
}

void Farm(const Rect& block, Random& rng, SceneBuilder& builder) {
    const Rect yard = RandomPatch(block.Inset(4.0), 45.0, 70.0, rng);
    const double yaw = rng.Uniform(-10.0, 10.0) * core::kRadiansPerDegree;
    const Rect house_area{yard.x0, yard.y0, yard.Center().x() - 4.0, yard.Center().y() - 4.0};
    // Drawn in GCC's order of the call's arguments (detail/random.hpp).
    const double house_height = rng.Uniform(6.0, 9.0);
    const double house_width = rng.Uniform(8.0, 11.0);
    const double house_length = rng.Uniform(10.0, 15.0);
    builder.StandingBox(house_area.Center(), yaw, house_length, house_width, house_height);
    const Rect barn_area{yard.Center().x() + 4.0, yard.y0, yard.x1, yard.Center().y() - 4.0};
    builder.StandingBox(barn_area.Center(), yaw, std::min(barn_area.Width() - 2.0, 24.0),
                        std::min(barn_area.Height() - 2.0, 14.0), rng.Uniform(6.0, 10.0));
    const Rect back{yard.x0, yard.Center().y() + 4.0, yard.x1, yard.y1};
    if (rng.Bernoulli(0.6)) {
        const Eigen::Vector2d silo = RandomPoint(back.Inset(4.0), rng);
        const double radius = rng.Uniform(2.5, 4.0);
        const double height = rng.Uniform(10.0, 18.0);
        builder.StandingCylinder(silo, radius, height);
        builder.Cone(silo, radius + 0.2, height, rng.Uniform(1.5, 3.0));
    }
    for (int k = rng.UniformInt(1, 3); k > 0; --k) {
        // Drawn in GCC's order of the call's arguments (detail/random.hpp).
        const double car_yaw = rng.Uniform(0.0, 2.0 * std::numbers::pi);
        builder.Car(RandomPoint(back.Inset(3.0), rng), car_yaw, rng);
    }
    for (int k = rng.UniformInt(2, 6); k > 0; --k) {
        // Drawn in GCC's order of the call's arguments (detail/random.hpp).
        const bool conifer = rng.Bernoulli(0.3);
        builder.Tree(RandomPoint(yard, rng), rng, conifer, 3.5);
    }
}

void Forest(const Rect& block, Random& rng, SceneBuilder& builder) {
    const Rect patch = RandomPatch(block.Inset(2.0), 35.0, 90.0, rng);
    const double spacing = rng.Uniform(4.5, 7.0);
    const double conifer_share = rng.Uniform(0.4, 0.9);
    for (double y = patch.y0; y < patch.y1; y += spacing) {
        for (double x = patch.x0; x < patch.x1; x += spacing) {
            if (!rng.Bernoulli(0.8)) continue;
            // Drawn in GCC's order of the call's arguments (detail/random.hpp).
            const double y_jitter = rng.Uniform(-1.5, 1.5);
            const double x_jitter = rng.Uniform(-1.5, 1.5);
            const Eigen::Vector2d at(std::clamp(x + x_jitter, patch.x0, patch.x1),
                                     std::clamp(y + y_jitter, patch.y0, patch.y1));
            builder.Tree(at, rng, rng.Bernoulli(conifer_share), 3.0);
        }
    }
}

void Orchard(const Rect& block, Random& rng, SceneBuilder& builder) {
    const Rect patch = RandomPatch(block.Inset(3.0), 40.0, 80.0, rng);
    const double spacing = rng.Uniform(5.0, 7.0);
    for (double y = patch.y0; y < patch.y1; y += spacing) {
        for (double x = patch.x0; x < patch.x1; x += spacing) {
            builder.Tree({x, y}, rng, false, 2.0);
        }
    }
}

void Field(const Rect& block, Random& rng, SceneBuilder& builder) {
    for (int k = rng.UniformInt(0, 3); k > 0; --k) {
        builder.Tree(RandomPoint(block.Inset(3.0), rng), rng, false, 3.5);
    }
    if (rng.Bernoulli(0.4)) {  // hay bales in a row
        const Rect row = RandomPatch(block.Inset(5.0), 10.0, 30.0, rng);
        for (double x = row.x0; x < row.x1; x += 3.0) {
            builder.StandingCylinder({x, row.y0}, 0.75, 1.2);
        }
    }
}

// Low stone walls along some block edges, with a gap for a field gate.
void StoneWalls(const Rect& block, Random& rng, SceneBuilder& builder) {
    const Rect w = block.Inset(1.0);
    const Eigen::Vector2d corners[4] = {{w.x0, w.y0}, {w.x1, w.y0}, {w.x1, w.y1}, {w.x0, w.y1}};
    for (int edge = 0; edge < 4; ++edge) {
        if (!rng.Bernoulli(0.3)) continue;
        const Eigen::Vector2d a = corners[edge];
        const Eigen::Vector2d b = corners[(edge + 1) % 4];
        const double gate = rng.Uniform(0.2, 0.8);
        const double height = rng.Uniform(0.7, 1.2);
        builder.Wall(a, a + (gate - 0.03) * (b - a), 0.6, height);
        builder.Wall(a + (gate + 0.03) * (b - a), b, 0.6, height);
    }
}

}  // namespace

void FillRuralBlock(const Rect& block, Random& rng, SceneBuilder& builder) {
    const double kind = rng.Uniform();
    if (kind < 0.35) {
        Field(block, rng, builder);
    } else if (kind < 0.6) {
        Farm(block, rng, builder);
    } else if (kind < 0.85) {
        Forest(block, rng, builder);
    } else {
        Orchard(block, rng, builder);
    }
    StoneWalls(block, rng, builder);
}

void FillRuralStreet(const StreetFrame& street, Random& rng, SceneBuilder& builder) {
    // Utility poles on one side, with a cross arm.
    const double pole_side = rng.Bernoulli(0.5) ? 1.0 : -1.0;
    for (double along = rng.Uniform(5.0, 40.0); along < street.length_m; along += 45.0) {
        const Eigen::Vector2d foot = street.At(along, pole_side * 9.0);
        const double height = rng.Uniform(8.5, 10.0);
        builder.StandingCylinder(foot, 0.14, height);
        builder.RaisedBox(foot, street.Yaw() + 0.5 * std::numbers::pi, 2.0, 0.12, height - 0.8,
                          height - 0.65);
    }
    for (const double side : {-1.0, 1.0}) {
        for (double along = rng.Uniform(0.0, 25.0); along < street.length_m; along += 50.0) {
            builder.StandingBox(street.At(along, side * 8.0), street.Yaw(), 0.12, 0.12, 1.0);
        }
        if (rng.Bernoulli(0.4)) {  // a tree row along this side
            for (double along = rng.Uniform(2.0, 8.0); along < street.length_m;
                 along += rng.Uniform(9.0, 14.0)) {
                // Drawn in GCC's order of the call's arguments (detail/random.hpp).
                const bool conifer = rng.Bernoulli(0.2);
                const double offset = 11.5 + rng.Uniform(-0.5, 0.5);
                builder.Tree(street.At(along, side * offset), rng, conifer, 3.5);
            }
        }
        if (rng.Bernoulli(0.3)) {
            const Eigen::Vector2d foot = street.At(rng.Uniform(2.0, 10.0), side * 8.6);
            builder.StandingCylinder(foot, 0.05, 2.5);
            builder.RaisedBox(foot, street.Yaw(), 0.05, 0.7, 1.8, 2.5);
        }
    }
}

}  // namespace lidarloop::sim::detail

// Room-and-pillar mine (like the Kvarntorp limestone mine): irregular rock pillars between
// drifts of equal width under a roof; boulders, pipes, electrical boxes and roof lamps along the
// drifts. Deliberately self-similar: every crossing looks much like every other one.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "lidarloop/core/angles.hpp"
#include "lidarloop/sim/detail/scene_builder.hpp"

namespace lidarloop::sim::detail {
namespace {

// Rock bulging out of a pillar face: a box reaching 1 m into the pillar and up to 0.5 m out.
void Bulge(const Rect& pillar, Random& rng, SceneBuilder& builder) {
    const int face = rng.UniformInt(0, 3);  // south, north, west, east
    const bool along_x = face < 2;
    const double length = rng.Uniform(1.0, 3.0);
    const double protrusion = rng.Uniform(0.15, 0.5);
    const double depth = 1.0 + protrusion;
    const double side = along_x ? pillar.Width() : pillar.Height();
    const double along = rng.Uniform(-0.5, 0.5) * (side - length);
    const double out = 0.5 * depth - 1.0;  // centre beyond the face (negative: inside)
    const Eigen::Vector2d c = pillar.Center();
    const Eigen::Vector2d centers[4] = {{c.x() + along, pillar.y0 - out},
                                        {c.x() + along, pillar.y1 + out},
                                        {pillar.x0 - out, c.y() + along},
                                        {pillar.x1 + out, c.y() + along}};
    const double yaw =
        (along_x ? 0.0 : 0.5 * std::numbers::pi) + rng.Uniform(-6.0, 6.0) * core::kRadiansPerDegree;
    const double top =
        rng.Bernoulli(0.5) ? builder.layout().ceiling_height_m + 1.0 : rng.Uniform(0.8, 3.5);
    builder.RaisedBox(centers[face], yaw, length, depth, -1.0, top);
}

}  // namespace

void FillMineBlock(const Rect& block, Random& rng, SceneBuilder& builder) {
    // The pillar: a slightly turned box that does not reach the block edge, whose faces are
    // roughened by bulges that stay within 0.6 m of the block edge (the drift side band).
    const Rect pillar{block.x0 + rng.Uniform(0.45, 0.7), block.y0 + rng.Uniform(0.45, 0.7),
                      block.x1 - rng.Uniform(0.45, 0.7), block.y1 - rng.Uniform(0.45, 0.7)};
    builder.SolidBox(pillar.Center(), rng.Uniform(-1.5, 1.5) * core::kRadiansPerDegree,
                     pillar.Width(), pillar.Height());
    for (int k = rng.UniformInt(3, 6); k > 0; --k) Bulge(pillar, rng, builder);
}

void FillMineStreet(const StreetFrame& street, Random& rng, SceneBuilder& builder) {
    const double ceiling = builder.layout().ceiling_height_m;
    for (const double side : {-1.0, 1.0}) {
        for (int k = rng.UniformInt(0, 3); k > 0; --k) {  // fallen rock against the wall
            const double radius = rng.Uniform(0.3, 0.6);
            const Eigen::Vector2d at =
                street.At(rng.Uniform(1.0, street.length_m - 1.0), side * (4.0 + radius));
            builder.Ellipsoid({at.x(), at.y(), 0.0},
                              {radius, radius * rng.Uniform(0.8, 1.0), rng.Uniform(0.25, 0.5)});
        }
        if (rng.Bernoulli(0.4)) {  // a ventilation pipe high on the wall
            builder.RaisedBox(street.At(0.5 * street.length_m, side * 4.65), street.Yaw(),
                              street.length_m, 0.5, ceiling - 1.2, ceiling - 0.7);
        }
        if (rng.Bernoulli(0.3)) {  // an electrical cabinet
            // Drawn in GCC's order of the call's arguments (detail/random.hpp).
            const double length = rng.Uniform(0.5, 1.0);
            const double along = rng.Uniform(1.0, street.length_m - 1.0);
            builder.RaisedBox(street.At(along, side * 4.8), street.Yaw(), length, 0.4, 0.9, 1.9);
        }
    }
    if (rng.Bernoulli(0.5)) {  // a lamp hanging from the roof, high above the vehicle
        builder.RaisedBox(street.At(0.5 * street.length_m, 0.0), street.Yaw(), 0.8, 0.2,
                          ceiling - 0.35, ceiling + 0.5);
    }
}

}  // namespace lidarloop::sim::detail

// Urban blocks: lots with box, L-shaped and turned buildings, roof structures and garden walls;
// streets with parked cars, street lights, trees and signs.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "lidarloop/core/angles.hpp"
#include "lidarloop/sim/detail/scene_builder.hpp"

namespace lidarloop::sim::detail {
namespace {

constexpr double kParkingOffset_m = 8.3;  // car centres; the driven road ends at 7.2 m
constexpr double kLightOffset_m = 9.9;
constexpr double kTreeOffset_m = 11.0;

// Splits [a, b] into one or two parts at 40-60 %.
std::vector<std::pair<double, double>> Split(double a, double b, Random& rng) {
    if (rng.Bernoulli(0.4)) return {{a, b}};
    const double cut = a + (b - a) * rng.Uniform(0.4, 0.6);
    return {{a, cut}, {cut, b}};
}

void LShapedBuilding(const Rect& f, double height, Random& rng, SceneBuilder& builder) {
    // A full-width wing along one side and a full-height wing along an adjacent one.
    const double depth = f.Height() * rng.Uniform(0.35, 0.55);
    const double width = f.Width() * rng.Uniform(0.35, 0.55);
    const bool south = rng.Bernoulli(0.5);
    const bool west = rng.Bernoulli(0.5);
    const Rect wing_a =
        south ? Rect{f.x0, f.y0, f.x1, f.y0 + depth} : Rect{f.x0, f.y1 - depth, f.x1, f.y1};
    const Rect wing_b =
        west ? Rect{f.x0, f.y0, f.x0 + width, f.y1} : Rect{f.x1 - width, f.y0, f.x1, f.y1};
    builder.StandingBox(wing_a.Center(), 0.0, wing_a.Width(), wing_a.Height(), height);
    builder.StandingBox(wing_b.Center(), 0.0, wing_b.Width(), wing_b.Height(),
                        height * rng.Uniform(0.6, 1.0));
}

void TurnedBuilding(const Rect& f, double height, Random& rng, SceneBuilder& builder) {
    const double sign = rng.Bernoulli(0.5) ? 1.0 : -1.0;
    const double yaw = sign * rng.Uniform(5.0, 20.0) * core::kRadiansPerDegree;
    double length = f.Width() * rng.Uniform(0.7, 0.95);
    double width = f.Height() * rng.Uniform(0.7, 0.95);
    const double c = std::cos(yaw);
    const double s = std::abs(std::sin(yaw));
    // Shrink until the turned footprint fits in the lot.
    const double fit = std::min(
        {1.0, f.Width() / (length * c + width * s), f.Height() / (length * s + width * c)});
    length *= fit;
    width *= fit;
    builder.StandingBox(f.Center(), yaw, length, width, height);
}

// Walls along the lot edges that face a street, with a gate in the middle.
void GardenWalls(const Rect& lot, const Rect& block, Random& rng, SceneBuilder& builder) {
    const double height = rng.Uniform(1.0, 2.2);
    const double inset = 0.3;
    const auto wall_with_gate = [&](Eigen::Vector2d a, Eigen::Vector2d b) {
        const Eigen::Vector2d mid = 0.5 * (a + b);
        const Eigen::Vector2d half_gate = 1.5 * (b - a).normalized();
        builder.Wall(a, mid - half_gate, 0.3, height);
        builder.Wall(mid + half_gate, b, 0.3, height);
    };
    if (lot.y0 == block.y0) wall_with_gate({lot.x0, lot.y0 + inset}, {lot.x1, lot.y0 + inset});
    if (lot.y1 == block.y1) wall_with_gate({lot.x0, lot.y1 - inset}, {lot.x1, lot.y1 - inset});
    if (lot.x0 == block.x0) wall_with_gate({lot.x0 + inset, lot.y0}, {lot.x0 + inset, lot.y1});
    if (lot.x1 == block.x1) wall_with_gate({lot.x1 - inset, lot.y0}, {lot.x1 - inset, lot.y1});
}

void Lot(const Rect& lot, const Rect& block, Random& rng, SceneBuilder& builder) {
    // Set back from the streets by 0-3 m, 1 m from the neighbouring lots.
    const double setback = rng.Bernoulli(0.5) ? rng.Uniform(0.0, 0.5) : rng.Uniform(1.5, 3.0);
    const auto edge = [&](double lot_edge, double block_edge) {
        return lot_edge == block_edge ? setback : 1.0;
    };
    const Rect f{lot.x0 + edge(lot.x0, block.x0), lot.y0 + edge(lot.y0, block.y0),
                 lot.x1 - edge(lot.x1, block.x1), lot.y1 - edge(lot.y1, block.y1)};
    if (f.Width() < 4.0 || f.Height() < 4.0) return;
    const double height = rng.Bernoulli(0.1) ? rng.Uniform(30.0, 45.0) : rng.Uniform(7.0, 24.0);
    const double style = rng.Uniform();
    if (style < 0.5) {
        builder.StandingBox(f.Center(), 0.0, f.Width(), f.Height(), height);
        if (rng.Bernoulli(0.5)) {  // a stair house or air conditioning plant on the roof
            // Drawn in GCC's order of the call's arguments (detail/random.hpp).
            const double y = rng.Uniform(f.y0 + 3.0, f.y1 - 3.0);
            const double x = rng.Uniform(f.x0 + 3.0, f.x1 - 3.0);
            const double top = height + rng.Uniform(1.5, 3.5);
            const double width = rng.Uniform(2.0, 5.0);
            const double length = rng.Uniform(2.0, 5.0);
            builder.RaisedBox({x, y}, 0.0, length, width, height - 0.5, top);
        }
    } else if (style < 0.85) {
        LShapedBuilding(f, height, rng, builder);
    } else {
        TurnedBuilding(f, height, rng, builder);
    }
    if (setback > 1.0) GardenWalls(lot, block, rng, builder);
}

void StreetLight(const StreetFrame& street, double along, double side, Random& rng,
                 SceneBuilder& builder) {
    const double height = rng.Uniform(6.5, 8.0);
    const Eigen::Vector2d foot = street.At(along, side * kLightOffset_m);
    builder.StandingCylinder(foot, rng.Uniform(0.1, 0.15), height);
    // The lamp arm reaches over the parking lane, not over the driven road.
    const Eigen::Vector2d arm = street.At(along, side * (kLightOffset_m - 0.7));
    builder.RaisedBox(arm, street.Yaw() + 0.5 * std::numbers::pi, 1.4, 0.3, height - 0.3, height);
}

void Sign(const Eigen::Vector2d& foot, double yaw, Random& rng, SceneBuilder& builder) {
    const double height = rng.Uniform(2.2, 2.8);
    builder.StandingCylinder(foot, 0.04, height);
    builder.RaisedBox(foot, yaw, 0.05, rng.Uniform(0.5, 0.8), height - 0.7, height);
}

}  // namespace

void FillUrbanBlock(const Rect& block, Random& rng, SceneBuilder& builder) {
    for (const auto& [x0, x1] : Split(block.x0, block.x1, rng)) {
        for (const auto& [y0, y1] : Split(block.y0, block.y1, rng)) {
            Lot({x0, y0, x1, y1}, block, rng, builder);
        }
    }
}

void FillUrbanStreet(const StreetFrame& street, Random& rng, SceneBuilder& builder) {
    for (const double side : {-1.0, 1.0}) {
        const double car_yaw = street.Yaw() + (side > 0.0 ? std::numbers::pi : 0.0);
        for (double along = 3.5; along + 3.0 < street.length_m; along += 6.0) {
            if (!rng.Bernoulli(0.45)) continue;
            const double jitter = rng.Uniform(-0.4, 0.4);
            builder.Car(street.At(along + jitter, side * kParkingOffset_m),
                        car_yaw + rng.Uniform(-2.0, 2.0) * core::kRadiansPerDegree, rng);
        }
        for (double along = rng.Uniform(2.0, 8.0); along < street.length_m; along += 24.0) {
            StreetLight(street, along, side, rng, builder);
        }
        for (double along = rng.Uniform(4.0, 10.0); along < street.length_m - 2.0;
             along += rng.Uniform(8.0, 14.0)) {
            if (!rng.Bernoulli(0.55)) continue;
            // Drawn in GCC's order of the call's arguments (detail/random.hpp).
            const bool conifer = rng.Bernoulli(0.1);
            const double offset = kTreeOffset_m + rng.Uniform(-0.3, 0.3);
            builder.Tree(street.At(along, side * offset), rng, conifer, 2.8);
        }
        if (rng.Bernoulli(0.5)) {
            Sign(street.At(rng.Uniform(1.0, 4.0), side * 9.3), street.Yaw(), rng, builder);
        }
        if (rng.Bernoulli(0.4)) {  // a bench or a rubbish bin
            // Drawn in GCC's order of the call's arguments (detail/random.hpp).
            const double cylinder_height = rng.Uniform(0.8, 1.1);
            const double radius = rng.Uniform(0.25, 0.4);
            const double offset = rng.Uniform(10.0, 11.5);
            const double along = rng.Uniform(5.0, street.length_m - 5.0);
            builder.StandingCylinder(street.At(along, side * offset), radius, cylinder_height);
        }
    }
}

}  // namespace lidarloop::sim::detail

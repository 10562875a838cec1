// Indoor floor: each block is one room or two, walled up to the ceiling, with doors onto the
// corridors (door leaves open into the room at random angles, some closed) and furniture; the
// corridors get radiators and fire extinguishers on their walls.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "lidarloop/core/angles.hpp"
#include "lidarloop/sim/detail/scene_builder.hpp"

namespace lidarloop::sim::detail {
namespace {

constexpr double kWall_m = 0.15;
constexpr double kDoorWidth_m = 0.9;
constexpr double kDoorHeight_m = 2.05;

// A wall along a -> b (centre line) with doors centred at the given distances from a. Door
// leaves are hinged at the gap's end nearer to a and open towards `inward`.
void WallWithDoors(const Eigen::Vector2d& a, const Eigen::Vector2d& b, std::vector<double> doors,
                   const Eigen::Vector2d& inward, Random& rng, SceneBuilder& builder,
                   std::vector<Rect>& keep_out) {
    const Eigen::Vector2d u = (b - a).normalized();
    const double length = (b - a).norm();
    const double wall_yaw = std::atan2(u.y(), u.x());
    const double ceiling = builder.layout().ceiling_height_m;
    std::sort(doors.begin(), doors.end());
    double start = 0.0;
    for (const double centre : doors) {
        const double gap0 = centre - 0.5 * kDoorWidth_m;
        builder.SolidWall(a + start * u, a + gap0 * u, kWall_m);
        builder.RaisedBox(a + centre * u, wall_yaw, kDoorWidth_m, kWall_m, kDoorHeight_m,
                          ceiling + 0.5);
        const Eigen::Vector2d hinge = a + gap0 * u;
        const double angle =
            rng.Bernoulli(0.15) ? 0.0 : rng.Uniform(20.0, 100.0) * core::kRadiansPerDegree;
        const double turn = (u.x() * inward.y() - u.y() * inward.x()) > 0.0 ? angle : -angle;
        const Eigen::Vector2d leaf(std::cos(wall_yaw + turn), std::sin(wall_yaw + turn));
        builder.RaisedBox(hinge + 0.5 * kDoorWidth_m * leaf, wall_yaw + turn, kDoorWidth_m, 0.04,
                          0.01, kDoorHeight_m - 0.02);
        const Eigen::Vector2d c = a + centre * u;
        keep_out.push_back({c.x() - 1.2, c.y() - 1.2, c.x() + 1.2, c.y() + 1.2});
        start = centre + 0.5 * kDoorWidth_m;
    }
    builder.SolidWall(a + start * u, a + length * u, kWall_m);
}

// Places a footprint of w x h somewhere in `room` clear of `taken`; false when 12 tries fail.
bool Place(const Rect& room, double w, double h, Random& rng, std::vector<Rect>& taken,
           Rect& placed) {
    if (w > room.Width() || h > room.Height()) return false;
    for (int attempt = 0; attempt < 12; ++attempt) {
        const double x = rng.Uniform(room.x0, room.x1 - w);
        const double y = rng.Uniform(room.y0, room.y1 - h);
        placed = {x, y, x + w, y + h};
        if (std::none_of(taken.begin(), taken.end(),
                         [&](const Rect& r) { return r.Overlaps(placed); })) {
            taken.push_back(placed.Inset(-0.3));
            return true;
        }
    }
    return false;
}

void Furnish(const Rect& room, Random& rng, SceneBuilder& builder, std::vector<Rect> taken) {
    Rect r;
    for (int k = rng.UniformInt(1, 3); k > 0; --k) {  // desks with a chair
        const bool turned = rng.Bernoulli(0.5);
        const double w = rng.Uniform(1.4, 1.8);
        const double d = rng.Uniform(0.7, 0.9);
        if (!Place(room, turned ? d : w, turned ? w : d, rng, taken, r)) continue;
        builder.StandingBox(r.Center(), 0.0, r.Width(), r.Height(), 0.74);
        const Eigen::Vector2d chair = r.Center() + (turned ? Eigen::Vector2d(d * 0.5 + 0.35, 0.0)
                                                           : Eigen::Vector2d(0.0, d * 0.5 + 0.35));
        builder.StandingBox(chair, rng.Uniform(-0.5, 0.5), 0.5, 0.5, 0.9);
    }
    for (int k = rng.UniformInt(0, 2); k > 0; --k) {  // cabinets and shelves
        const bool turned = rng.Bernoulli(0.5);
        const double w = rng.Uniform(0.8, 2.0);
        if (!Place(room, turned ? 0.45 : w, turned ? w : 0.45, rng, taken, r)) continue;
        builder.StandingBox(r.Center(), 0.0, r.Width(), r.Height(), rng.Uniform(1.6, 2.2));
    }
    if (rng.Bernoulli(0.35) && Place(room, 1.1, 1.1, rng, taken, r)) {
        builder.StandingCylinder(r.Center(), rng.Uniform(0.4, 0.55), 0.73);
    }
    if (rng.Bernoulli(0.5) && Place(room, 0.8, 0.8, rng, taken, r)) {
        builder.StandingCylinder(r.Center(), 0.2, 0.45);
        builder.Ellipsoid({r.Center().x(), r.Center().y(), 0.9}, {0.35, 0.35, 0.45});
    }
}

}  // namespace

namespace {

// Where the doors go: distances along the south, north, west and east walls (each measured
// from its west or south end). Every room gets a door onto a corridor. `split` 0: one room;
// 1: two rooms, wall at x = mid; 2: two rooms, wall at y = mid.
std::array<std::vector<double>, 4> ChooseDoors(double w, int split, Random& rng) {
    std::array<std::vector<double>, 4> doors;
    const auto door = [&](int edge, double lo, double hi) {
        doors[edge].push_back(rng.Uniform(lo + 0.8, hi - 0.8));
    };
    const double half = 0.5 * w;
    if (split == 0) {
        const int first = rng.UniformInt(0, 3);
        door(first, 0.0, w);
        if (rng.Bernoulli(0.5)) door((first + rng.UniformInt(1, 3)) % 4, 0.0, w);
        return doors;
    }
    // The first edge of each list is the room's own full wall, the others its half walls.
    const int low_edges[3] = {split == 1 ? 2 : 0, split == 1 ? 0 : 2, split == 1 ? 1 : 3};
    const int high_edges[3] = {split == 1 ? 3 : 1, split == 1 ? 0 : 2, split == 1 ? 1 : 3};
    const int pick_low = rng.UniformInt(0, 2);
    const int pick_high = rng.UniformInt(0, 2);
    door(low_edges[pick_low], 0.0, pick_low == 0 ? w : half);
    door(high_edges[pick_high], pick_high == 0 ? 0.0 : half, w);
    return doors;
}

// The wall between the two rooms of a split block, and their furniture.
void SplitRooms(const Rect& block, int split, Random& rng, SceneBuilder& builder,
                std::vector<Rect>& keep_out) {
    const Rect inner = block.Inset(kWall_m + 0.05);
    const Eigen::Vector2d c = block.Center();
    const Eigen::Vector2d a = split == 1 ? Eigen::Vector2d(c.x(), block.y0 + kWall_m)
                                         : Eigen::Vector2d(block.x0 + kWall_m, c.y());
    const Eigen::Vector2d b = split == 1 ? Eigen::Vector2d(c.x(), block.y1 - kWall_m)
                                         : Eigen::Vector2d(block.x1 - kWall_m, c.y());
    std::vector<double> inner_doors;
    if (rng.Bernoulli(0.7)) inner_doors.push_back(rng.Uniform(1.0, (b - a).norm() - 1.0));
    const Eigen::Vector2d inward = split == 1 ? Eigen::Vector2d::UnitX() : Eigen::Vector2d::UnitY();
    WallWithDoors(a, b, inner_doors, inward, rng, builder, keep_out);
    const double m = 0.5 * kWall_m + 0.05;
    if (split == 1) {
        Furnish({inner.x0, inner.y0, c.x() - m, inner.y1}, rng, builder, keep_out);
        Furnish({c.x() + m, inner.y0, inner.x1, inner.y1}, rng, builder, keep_out);
    } else {
        Furnish({inner.x0, inner.y0, inner.x1, c.y() - m}, rng, builder, keep_out);
        Furnish({inner.x0, c.y() + m, inner.x1, inner.y1}, rng, builder, keep_out);
    }
}

}  // namespace

void FillIndoorBlock(const Rect& block, Random& rng, SceneBuilder& builder) {
    // Walls on the block edges, with doors; a split wall makes two rooms.
    const int split = rng.UniformInt(0, 2);
    const auto doors = ChooseDoors(block.Width(), split, rng);
    const double t = 0.5 * kWall_m;
    const Eigen::Vector2d sw(block.x0, block.y0);
    const Eigen::Vector2d se(block.x1, block.y0);
    const Eigen::Vector2d nw(block.x0, block.y1);
    const Eigen::Vector2d ne(block.x1, block.y1);
    const Eigen::Vector2d up = Eigen::Vector2d::UnitY();
    const Eigen::Vector2d right = Eigen::Vector2d::UnitX();
    std::vector<Rect> keep_out;
    WallWithDoors(sw + t * up, se + t * up, doors[0], up, rng, builder, keep_out);
    WallWithDoors(nw - t * up, ne - t * up, doors[1], -up, rng, builder, keep_out);
    WallWithDoors(sw + t * right, nw + t * right, doors[2], right, rng, builder, keep_out);
    WallWithDoors(se - t * right, ne - t * right, doors[3], -right, rng, builder, keep_out);
    if (split == 0) {
        Furnish(block.Inset(kWall_m + 0.05), rng, builder, keep_out);
    } else {
        SplitRooms(block, split, rng, builder, keep_out);
    }
}

void FillIndoorStreet(const StreetFrame& street, Random& rng, SceneBuilder& builder) {
    // Items on the corridor walls stay within 0.15 m of them (the corridor is 3 m wide and the
    // robot keeps to its middle 2.7 m).
    const double wall = builder.layout().corridor_half_width_m;
    for (const double side : {-1.0, 1.0}) {
        if (rng.Bernoulli(0.4)) {
            builder.RaisedBox(
                street.At(rng.Uniform(1.0, street.length_m - 1.0), side * (wall - 0.05)),
                street.Yaw(), 1.0, 0.1, 0.15, 0.75);
        }
        if (rng.Bernoulli(0.25)) {
            builder.RaisedBox(
                street.At(rng.Uniform(0.5, street.length_m - 0.5), side * (wall - 0.075)),
                street.Yaw(), 0.2, 0.15, 0.9, 1.4);
        }
    }
}

}  // namespace lidarloop::sim::detail

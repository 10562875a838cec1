#pragma once

// Internal: helpers that place objects on a terrain, and the content generators of each scene
// type (scene_urban.cpp, scene_rural.cpp, scene_mine.cpp, scene_indoor.cpp). Not installed.

#include <vector>

#include <Eigen/Core>

#include "lidarloop/sim/detail/random.hpp"
#include "lidarloop/sim/scene.hpp"
#include "lidarloop/sim/shapes.hpp"

namespace lidarloop::sim::detail {

/// An axis-aligned rectangle in x-y, metres.
struct Rect {
    double x0 = 0.0;
    double y0 = 0.0;
    double x1 = 0.0;
    double y1 = 0.0;

    double Width() const { return x1 - x0; }
    double Height() const { return y1 - y0; }
    Eigen::Vector2d Center() const { return {0.5 * (x0 + x1), 0.5 * (y0 + y1)}; }
    Rect Inset(double margin) const { return {x0 + margin, y0 + margin, x1 - margin, y1 - margin}; }
    bool Overlaps(const Rect& other) const {
        return x0 < other.x1 && other.x0 < x1 && y0 < other.y1 && other.y0 < y1;
    }
};

/// The part of a street between two intersections: points by their distance along it from the
/// end of the first intersection and their offset to the left of its direction (negative:
/// right).
struct StreetFrame {
    Eigen::Vector2d start_m = Eigen::Vector2d::Zero();
    Eigen::Vector2d direction = Eigen::Vector2d::UnitX();  ///< unit, along the street
    double length_m = 0.0;

    Eigen::Vector2d Left() const { return {-direction.y(), direction.x()}; }
    Eigen::Vector2d At(double along_m, double left_m) const {
        return start_m + along_m * direction + left_m * Left();
    }
    double Yaw() const;
};

/// Places objects on the ground of a scene. Heights are above the local ground; bases are sunk
/// into the ground by the slope over the footprint so that no gap shows under them on a slope.
class SceneBuilder {
public:
    SceneBuilder(const Terrain& terrain, const SceneLayout& layout, std::vector<Shape>& objects)
        : terrain_(terrain), layout_(layout), objects_(objects) {}

    const SceneLayout& layout() const { return layout_; }
    double Ground(const Eigen::Vector2d& p) const { return terrain_.Height(p.x(), p.y()); }

    /// A box from below the ground to `height` above it; `length` along yaw, `width` across.
    void StandingBox(const Eigen::Vector2d& center, double yaw, double length, double width,
                     double height);
    /// A box from `bottom` to `top` above the ground at its centre.
    void RaisedBox(const Eigen::Vector2d& center, double yaw, double length, double width,
                   double bottom, double top);
    /// A box from below the lowest ground to above the highest ceiling (pillars, room walls).
    void SolidBox(const Eigen::Vector2d& center, double yaw, double length, double width);
    /// A wall of `thickness` from a to b (both at its centre line), `height` above the ground.
    void Wall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double thickness, double height);
    /// A wall from a to b from below the ground to above the ceiling.
    void SolidWall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double thickness);
    void StandingCylinder(const Eigen::Vector2d& center, double radius, double height);
    void RaisedCylinder(const Eigen::Vector2d& center, double radius, double bottom, double top);
    void Cone(const Eigen::Vector2d& center, double base_radius, double bottom, double height);
    void Ellipsoid(const Eigen::Vector3d& center_above_ground, const Eigen::Vector3d& radii);

    /// A deciduous tree (trunk and ellipsoid crown) or a conifer (trunk and cone), crown radius
    /// at most `max_crown_radius`.
    void Tree(const Eigen::Vector2d& center, Random& rng, bool conifer, double max_crown_radius);
    /// A parked car: body and cabin, about 4.5 m x 1.8 m x 1.5 m.
    void Car(const Eigen::Vector2d& center, double yaw, Random& rng);

private:
    double Sink(double radius) const { return terrain_.max_slope() * radius + 0.3; }

    const Terrain& terrain_;
    const SceneLayout& layout_;
    std::vector<Shape>& objects_;
};

void FillUrbanBlock(const Rect& block, Random& rng, SceneBuilder& builder);
void FillUrbanStreet(const StreetFrame& street, Random& rng, SceneBuilder& builder);
void FillRuralBlock(const Rect& block, Random& rng, SceneBuilder& builder);
void FillRuralStreet(const StreetFrame& street, Random& rng, SceneBuilder& builder);
void FillMineBlock(const Rect& block, Random& rng, SceneBuilder& builder);
void FillMineStreet(const StreetFrame& street, Random& rng, SceneBuilder& builder);
void FillIndoorBlock(const Rect& block, Random& rng, SceneBuilder& builder);
void FillIndoorStreet(const StreetFrame& street, Random& rng, SceneBuilder& builder);

}  // namespace lidarloop::sim::detail

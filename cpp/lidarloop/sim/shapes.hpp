#pragma once

#include <limits>
#include <variant>

#include <Eigen/Core>

namespace lidarloop::sim {

/// Distance returned by the ray casting functions when nothing is hit.
inline constexpr double kNoHit = std::numeric_limits<double>::infinity();

/// A half-line origin + t * direction, t >= 0, in the world frame (metres). `direction` must
/// have unit length, so that t is the range in metres.
struct Ray {
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
    Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
};

/// A solid box with a vertical z axis, turned by `yaw_rad` about z (buildings, walls, cars).
struct Box {
    Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d half_extent_m = Eigen::Vector3d::Ones();  ///< along the box's own x, y, z
    double yaw_rad = 0.0;  ///< rotation of the box's x axis from the world x axis, about z
};

/// A solid vertical cylinder (poles, trunks, silos).
struct Cylinder {
    Eigen::Vector2d center_xy_m = Eigen::Vector2d::Zero();
    double radius_m = 1.0;
    double z_min_m = 0.0;  ///< bottom cap height
    double z_max_m = 1.0;  ///< top cap height
};

/// A solid vertical cone with its apex up (conifer crowns, roofs of silos).
struct Cone {
    Eigen::Vector2d center_xy_m = Eigen::Vector2d::Zero();
    double base_radius_m = 1.0;
    double z_base_m = 0.0;  ///< height of the base disk
    double height_m = 1.0;  ///< apex at z_base_m + height_m
};

/// A solid axis-aligned ellipsoid (tree crowns, boulders).
struct Ellipsoid {
    Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d radii_m = Eigen::Vector3d::Ones();  ///< semi-axes along world x, y, z
};

/// Any object of a simulated world.
using Shape = std::variant<Box, Cylinder, Cone, Ellipsoid>;

/// Axis-aligned bounding box, world frame, metres.
struct Aabb {
    Eigen::Vector3d min_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d max_m = Eigen::Vector3d::Zero();
};

/// Exact ray-solid intersections: the smallest t > 0 at which the ray crosses the surface (the
/// entry, or the exit when the origin is inside), kNoHit when it misses. Thread-safe.
double Intersect(const Ray& ray, const Box& box);
double Intersect(const Ray& ray, const Cylinder& cylinder);
double Intersect(const Ray& ray, const Cone& cone);
double Intersect(const Ray& ray, const Ellipsoid& ellipsoid);
double Intersect(const Ray& ray, const Shape& shape);

/// True when `point_m` is inside the shape grown by `margin_m` (>= 0) in every direction. For
/// cones and ellipsoids the growth is approximate (the shape scaled out), good for clearance
/// checks, not for geometry.
bool Contains(const Shape& shape, const Eigen::Vector3d& point_m, double margin_m = 0.0);

/// The tight axis-aligned bounds of a shape.
Aabb Bounds(const Shape& shape);

}  // namespace lidarloop::sim

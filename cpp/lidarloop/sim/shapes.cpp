#include "lidarloop/sim/shapes.hpp"

#include <algorithm>
#include <cmath>

#include "lidarloop/sim/detail/intersect.hpp"

namespace lidarloop::sim {
namespace {

// Hits closer than this are the surface the ray starts on, not a new crossing.
constexpr double kMinT = 1e-9;
constexpr double kTinyRayTerm = 1e-15;

// The smaller accepted root of a t^2 + 2 h t + c = 0 (half-b form), kNoHit if none.
template <typename Accept>
double SmallestRoot(double a, double h, double c, Accept accept) {
    if (std::abs(a) < kTinyRayTerm) {
        if (std::abs(h) < kTinyRayTerm) return kNoHit;
        const double t = -c / (2.0 * h);
        return t > kMinT && accept(t) ? t : kNoHit;
    }
    const double discriminant = h * h - a * c;
    if (discriminant < 0.0) return kNoHit;
    const double root = std::sqrt(discriminant);
    double t0 = (-h - root) / a;
    double t1 = (-h + root) / a;
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > kMinT && accept(t0)) return t0;
    if (t1 > kMinT && accept(t1)) return t1;
    return kNoHit;
}

// The crossing of the horizontal disk of radius r about (cx, cy) at height z, kNoHit if none.
double IntersectDisk(const Ray& ray, double cx, double cy, double z, double r) {
    if (std::abs(ray.direction.z()) < kTinyRayTerm) return kNoHit;
    const double t = (z - ray.origin.z()) / ray.direction.z();
    if (t <= kMinT) return kNoHit;
    const double x = ray.origin.x() + t * ray.direction.x() - cx;
    const double y = ray.origin.y() + t * ray.direction.y() - cy;
    return x * x + y * y <= r * r ? t : kNoHit;
}

}  // namespace

namespace detail {

double IntersectBox(const Ray& ray, const Box& box, double cos_yaw, double sin_yaw) {
    // Slab test in the box's frame (Kay and Kajiya 1986).
    const Eigen::Vector3d p = ray.origin - box.center_m;
    const Eigen::Vector3d& d = ray.direction;
    const double origin[3] = {cos_yaw * p.x() + sin_yaw * p.y(), -sin_yaw * p.x() + cos_yaw * p.y(),
                              p.z()};
    const double direction[3] = {cos_yaw * d.x() + sin_yaw * d.y(),
                                 -sin_yaw * d.x() + cos_yaw * d.y(), d.z()};
    double t_near = -kNoHit;
    double t_far = kNoHit;
    for (int axis = 0; axis < 3; ++axis) {
        const double half = box.half_extent_m[axis];
        if (std::abs(direction[axis]) < kTinyRayTerm) {
            if (std::abs(origin[axis]) > half) return kNoHit;
            continue;
        }
        const double inverse = 1.0 / direction[axis];
        double t0 = (-half - origin[axis]) * inverse;
        double t1 = (half - origin[axis]) * inverse;
        if (t0 > t1) std::swap(t0, t1);
        t_near = std::max(t_near, t0);
        t_far = std::min(t_far, t1);
        if (t_near > t_far) return kNoHit;
    }
    if (t_far <= kMinT) return kNoHit;
    return t_near > kMinT ? t_near : t_far;
}

}  // namespace detail

double Intersect(const Ray& ray, const Box& box) {
    return detail::IntersectBox(ray, box, std::cos(box.yaw_rad), std::sin(box.yaw_rad));
}

double Intersect(const Ray& ray, const Cylinder& cylinder) {
    const Eigen::Vector3d& o = ray.origin;
    const Eigen::Vector3d& d = ray.direction;
    const double px = o.x() - cylinder.center_xy_m.x();
    const double py = o.y() - cylinder.center_xy_m.y();
    const double r = cylinder.radius_m;
    const double side = SmallestRoot(d.x() * d.x() + d.y() * d.y(), px * d.x() + py * d.y(),
                                     px * px + py * py - r * r, [&](double t) {
                                         const double z = o.z() + t * d.z();
                                         return z >= cylinder.z_min_m && z <= cylinder.z_max_m;
                                     });
    const double cx = cylinder.center_xy_m.x();
    const double cy = cylinder.center_xy_m.y();
    return std::min({side, IntersectDisk(ray, cx, cy, cylinder.z_min_m, r),
                     IntersectDisk(ray, cx, cy, cylinder.z_max_m, r)});
}

double Intersect(const Ray& ray, const Cone& cone) {
    // Surface x^2 + y^2 = k^2 w^2 with w = z_apex - z the depth below the apex, 0 <= w <= H.
    const Eigen::Vector3d& o = ray.origin;
    const Eigen::Vector3d& d = ray.direction;
    const double k = cone.base_radius_m / cone.height_m;
    const double k2 = k * k;
    const double px = o.x() - cone.center_xy_m.x();
    const double py = o.y() - cone.center_xy_m.y();
    const double qa = cone.z_base_m + cone.height_m - o.z();
    const double a = d.x() * d.x() + d.y() * d.y() - k2 * d.z() * d.z();
    const double h = px * d.x() + py * d.y() + k2 * qa * d.z();
    const double c = px * px + py * py - k2 * qa * qa;
    const double side = SmallestRoot(a, h, c, [&](double t) {
        const double w = qa - t * d.z();
        return w >= 0.0 && w <= cone.height_m;
    });
    return std::min(side, IntersectDisk(ray, cone.center_xy_m.x(), cone.center_xy_m.y(),
                                        cone.z_base_m, cone.base_radius_m));
}

double Intersect(const Ray& ray, const Ellipsoid& ellipsoid) {
    // Scale the ellipsoid to the unit sphere; t is unchanged by the scaling.
    const Eigen::Vector3d p = (ray.origin - ellipsoid.center_m).cwiseQuotient(ellipsoid.radii_m);
    const Eigen::Vector3d d = ray.direction.cwiseQuotient(ellipsoid.radii_m);
    return SmallestRoot(d.squaredNorm(), p.dot(d), p.squaredNorm() - 1.0,
                        [](double) { return true; });
}

double Intersect(const Ray& ray, const Shape& shape) {
    return std::visit([&ray](const auto& s) { return Intersect(ray, s); }, shape);
}

namespace {

bool ContainsShape(const Box& box, const Eigen::Vector3d& point, double margin) {
    const Eigen::Vector3d p = point - box.center_m;
    const double c = std::cos(box.yaw_rad);
    const double s = std::sin(box.yaw_rad);
    const Eigen::Vector3d local(c * p.x() + s * p.y(), -s * p.x() + c * p.y(), p.z());
    return (local.cwiseAbs().array() <= box.half_extent_m.array() + margin).all();
}

bool ContainsShape(const Cylinder& cylinder, const Eigen::Vector3d& point, double margin) {
    return (point.head<2>() - cylinder.center_xy_m).norm() <= cylinder.radius_m + margin &&
           point.z() >= cylinder.z_min_m - margin && point.z() <= cylinder.z_max_m + margin;
}

bool ContainsShape(const Cone& cone, const Eigen::Vector3d& point, double margin) {
    const double above_base = point.z() - cone.z_base_m;
    if (above_base < -margin || above_base > cone.height_m + margin) return false;
    const double radius =
        cone.base_radius_m * std::clamp(1.0 - above_base / cone.height_m, 0.0, 1.0);
    return (point.head<2>() - cone.center_xy_m).norm() <= radius + margin;
}

bool ContainsShape(const Ellipsoid& ellipsoid, const Eigen::Vector3d& point, double margin) {
    const Eigen::Vector3d grown = ellipsoid.radii_m.array() + margin;
    return (point - ellipsoid.center_m).cwiseQuotient(grown).squaredNorm() <= 1.0;
}

Aabb ShapeBounds(const Box& box) {
    const double c = std::abs(std::cos(box.yaw_rad));
    const double s = std::abs(std::sin(box.yaw_rad));
    const Eigen::Vector3d& h = box.half_extent_m;
    const Eigen::Vector3d extent(c * h.x() + s * h.y(), s * h.x() + c * h.y(), h.z());
    return {box.center_m - extent, box.center_m + extent};
}

Aabb ShapeBounds(const Cylinder& cylinder) {
    const Eigen::Vector2d& c = cylinder.center_xy_m;
    const double r = cylinder.radius_m;
    return {{c.x() - r, c.y() - r, cylinder.z_min_m}, {c.x() + r, c.y() + r, cylinder.z_max_m}};
}

Aabb ShapeBounds(const Cone& cone) {
    const Eigen::Vector2d& c = cone.center_xy_m;
    const double r = cone.base_radius_m;
    return {{c.x() - r, c.y() - r, cone.z_base_m},
            {c.x() + r, c.y() + r, cone.z_base_m + cone.height_m}};
}

Aabb ShapeBounds(const Ellipsoid& ellipsoid) {
    return {ellipsoid.center_m - ellipsoid.radii_m, ellipsoid.center_m + ellipsoid.radii_m};
}

}  // namespace

bool Contains(const Shape& shape, const Eigen::Vector3d& point_m, double margin_m) {
    return std::visit([&](const auto& s) { return ContainsShape(s, point_m, margin_m); }, shape);
}

Aabb Bounds(const Shape& shape) {
    return std::visit([](const auto& s) { return ShapeBounds(s); }, shape);
}

}  // namespace lidarloop::sim

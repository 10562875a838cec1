#include <algorithm>
#include <cmath>
#include <numbers>

#include "lidarloop/sim/detail/scene_builder.hpp"

namespace lidarloop::sim::detail {

double StreetFrame::Yaw() const { return std::atan2(direction.y(), direction.x()); }

void SceneBuilder::StandingBox(const Eigen::Vector2d& center, double yaw, double length,
                               double width, double height) {
    const double sink = Sink(0.5 * std::hypot(length, width));
    RaisedBox(center, yaw, length, width, -sink, height);
}

void SceneBuilder::RaisedBox(const Eigen::Vector2d& center, double yaw, double length, double width,
                             double bottom, double top) {
    const double ground = Ground(center);
    const double z0 = ground + bottom;
    const double z1 = ground + top;
    objects_.push_back(Box{{center.x(), center.y(), 0.5 * (z0 + z1)},
                           {0.5 * length, 0.5 * width, 0.5 * (z1 - z0)},
                           yaw});
}

void SceneBuilder::SolidBox(const Eigen::Vector2d& center, double yaw, double length,
                            double width) {
    const double z0 = terrain_.min_height_m() - 2.0;
    const double z1 = terrain_.max_height_m() + layout_.ceiling_height_m + 2.0;
    objects_.push_back(Box{{center.x(), center.y(), 0.5 * (z0 + z1)},
                           {0.5 * length, 0.5 * width, 0.5 * (z1 - z0)},
                           yaw});
}

void SceneBuilder::Wall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double thickness,
                        double height) {
    const Eigen::Vector2d d = b - a;
    StandingBox(0.5 * (a + b), std::atan2(d.y(), d.x()), d.norm(), thickness, height);
}

void SceneBuilder::SolidWall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double thickness) {
    const Eigen::Vector2d d = b - a;
    SolidBox(0.5 * (a + b), std::atan2(d.y(), d.x()), d.norm(), thickness);
}

void SceneBuilder::StandingCylinder(const Eigen::Vector2d& center, double radius, double height) {
    RaisedCylinder(center, radius, -Sink(radius), height);
}

void SceneBuilder::RaisedCylinder(const Eigen::Vector2d& center, double radius, double bottom,
                                  double top) {
    const double ground = Ground(center);
    objects_.push_back(Cylinder{center, radius, ground + bottom, ground + top});
}

void SceneBuilder::Cone(const Eigen::Vector2d& center, double base_radius, double bottom,
                        double height) {
    objects_.push_back(sim::Cone{center, base_radius, Ground(center) + bottom, height});
}

void SceneBuilder::Ellipsoid(const Eigen::Vector3d& center_above_ground,
                             const Eigen::Vector3d& radii) {
    Eigen::Vector3d center = center_above_ground;
    center.z() += Ground(center.head<2>());
    objects_.push_back(sim::Ellipsoid{center, radii});
}

void SceneBuilder::Tree(const Eigen::Vector2d& center, Random& rng, bool conifer,
                        double max_crown_radius) {
    const double trunk_radius = rng.Uniform(0.12, 0.3);
    if (conifer) {
        const double crown_radius = std::min(max_crown_radius, rng.Uniform(1.2, 2.8));
        const double crown_bottom = rng.Uniform(1.0, 2.5);
        StandingCylinder(center, trunk_radius, crown_bottom + 0.5);
        Cone(center, crown_radius, crown_bottom, crown_radius * rng.Uniform(2.5, 4.5));
        return;
    }
    const double trunk_height = rng.Uniform(1.8, 3.2);
    const double crown_radius = std::min(max_crown_radius, rng.Uniform(1.5, 3.2));
    const double crown_half_height = rng.Uniform(1.5, 3.0);
    StandingCylinder(center, trunk_radius, trunk_height + 0.5);
    Ellipsoid({center.x(), center.y(), trunk_height + 0.6 * crown_half_height},
              {crown_radius, crown_radius * rng.Uniform(0.85, 1.0), crown_half_height});
}

void SceneBuilder::Car(const Eigen::Vector2d& center, double yaw, Random& rng) {
    const double length = rng.Uniform(3.9, 4.9);
    const double width = rng.Uniform(1.7, 1.9);
    const double body_height = rng.Uniform(0.9, 1.1);
    StandingBox(center, yaw, length, width, body_height);
    const Eigen::Vector2d forward(std::cos(yaw), std::sin(yaw));
    const double cabin_length = length * rng.Uniform(0.45, 0.6);
    const double cabin_shift = rng.Uniform(-0.1, 0.05) * length;  // cabins sit a bit back
    RaisedBox(center + cabin_shift * forward, yaw, cabin_length, width * 0.9, body_height - 0.05,
              body_height + rng.Uniform(0.4, 0.6));
}

}  // namespace lidarloop::sim::detail

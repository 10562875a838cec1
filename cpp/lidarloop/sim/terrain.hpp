#pragma once

#include <vector>

#include <Eigen/Core>

#include "lidarloop/sim/shapes.hpp"

namespace lidarloop::sim {

/// One sinusoid of a terrain: amplitude_m * sin(wavenumber . (x, y) + phase_rad).
struct TerrainWave {
    double amplitude_m = 0.0;
    Eigen::Vector2d wavenumber_rad_per_m = Eigen::Vector2d::Zero();  ///< 2 pi / wavelength
    double phase_rad = 0.0;
};

/// A smooth analytic ground surface z = h(x, y) = base + sum of sinusoids, world frame, metres:
/// gentle rolling slopes without a mesh. Flat (z = base) without waves. Immutable, thread-safe.
class Terrain {
public:
    Terrain() = default;
    explicit Terrain(std::vector<TerrainWave> waves, double base_height_m = 0.0);

    double Height(double x_m, double y_m) const;
    /// (dh/dx, dh/dy), dimensionless.
    Eigen::Vector2d Gradient(double x_m, double y_m) const;
    /// Height and Gradient in one pass.
    void HeightAndGradient(double x_m, double y_m, double& height_m,
                           Eigen::Vector2d& gradient) const;

    /// Upper bound of |grad h| anywhere (sum of amplitude x wavenumber).
    double max_slope() const { return max_slope_; }
    double min_height_m() const { return base_height_m_ - amplitude_sum_m_; }
    double max_height_m() const { return base_height_m_ + amplitude_sum_m_; }
    const std::vector<TerrainWave>& waves() const { return waves_; }

    /// First crossing t in (0, t_max_m] of `ray` with the surface z = h(x, y) + offset_m, met from
    /// above (`from_below` false: the ground) or from below (true: a ceiling offset_m above the
    /// ground); kNoHit when there is none. Marches with steps that the bounds of the slope and
    /// curvature along the ray keep from passing a crossing (near the surface they are Newton
    /// steps), to within 1e-7 m of it. A ray starting on the wrong side of the surface returns 0.
    double Intersect(const Ray& ray, double offset_m, bool from_below, double t_max_m) const;

private:
    std::vector<TerrainWave> waves_;
    double base_height_m_ = 0.0;
    double max_slope_ = 0.0;
    double amplitude_sum_m_ = 0.0;
};

}  // namespace lidarloop::sim

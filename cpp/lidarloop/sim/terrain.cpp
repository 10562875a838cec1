#include "lidarloop/sim/terrain.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace lidarloop::sim {
namespace {

constexpr double kTolerance_m = 1e-7;
constexpr int kMaxSteps = 200;

// The signed distance of the ray point at t from the surface, measured along z, positive on the
// side the ray starts from.
class Distance {
public:
    Distance(const Terrain& terrain, const Ray& ray, double offset_m, double sign)
        : terrain_(terrain), ray_(ray), offset_m_(offset_m), sign_(sign) {}

    double operator()(double t) const {
        const Eigen::Vector3d p = ray_.origin + t * ray_.direction;
        return sign_ * (p.z() - terrain_.Height(p.x(), p.y()) - offset_m_);
    }

    /// f(t) and f'(t) together (one sine and cosine per wave).
    std::pair<double, double> ValueAndSlope(double t) const {
        const Eigen::Vector3d p = ray_.origin + t * ray_.direction;
        double height = 0.0;
        Eigen::Vector2d gradient;
        terrain_.HeightAndGradient(p.x(), p.y(), height, gradient);
        return {sign_ * (p.z() - height - offset_m_),
                sign_ * (ray_.direction.z() - gradient.dot(ray_.direction.head<2>()))};
    }

private:
    const Terrain& terrain_;
    const Ray& ray_;
    double offset_m_;
    double sign_;
};

// A root of f in [a, b] with f(a) > 0 >= f(b), by the Illinois variant of false position.
double Refine(const Distance& f, double a, double fa, double b, double fb) {
    int side = 0;
    for (int i = 0; i < 60 && b - a > kTolerance_m; ++i) {
        const double t = (a * fb - b * fa) / (fb - fa);
        const double ft = f(t);
        if (std::abs(ft) < kTolerance_m) return t;
        if (ft > 0.0) {
            a = t;
            fa = ft;
            if (side == 1) fb *= 0.5;
            side = 1;
        } else {
            b = t;
            fb = ft;
            if (side == -1) fa *= 0.5;
            side = -1;
        }
    }
    return b;
}

}  // namespace

Terrain::Terrain(std::vector<TerrainWave> waves, double base_height_m)
    : waves_(std::move(waves)), base_height_m_(base_height_m) {
    for (const auto& wave : waves_) {
        max_slope_ += std::abs(wave.amplitude_m) * wave.wavenumber_rad_per_m.norm();
        amplitude_sum_m_ += std::abs(wave.amplitude_m);
    }
}

double Terrain::Height(double x_m, double y_m) const {
    double z = base_height_m_;
    for (const auto& wave : waves_) {
        const Eigen::Vector2d& k = wave.wavenumber_rad_per_m;
        z += wave.amplitude_m * std::sin(k.x() * x_m + k.y() * y_m + wave.phase_rad);
    }
    return z;
}

void Terrain::HeightAndGradient(double x_m, double y_m, double& height_m,
                                Eigen::Vector2d& gradient) const {
    height_m = base_height_m_;
    gradient.setZero();
    for (const auto& wave : waves_) {
        const Eigen::Vector2d& k = wave.wavenumber_rad_per_m;
        const double phase = k.x() * x_m + k.y() * y_m + wave.phase_rad;
        height_m += wave.amplitude_m * std::sin(phase);
        gradient += wave.amplitude_m * std::cos(phase) * k;
    }
}

Eigen::Vector2d Terrain::Gradient(double x_m, double y_m) const {
    Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
    for (const auto& wave : waves_) {
        const Eigen::Vector2d& k = wave.wavenumber_rad_per_m;
        gradient += wave.amplitude_m * std::cos(k.x() * x_m + k.y() * y_m + wave.phase_rad) * k;
    }
    return gradient;
}

double Terrain::Intersect(const Ray& ray, double offset_m, bool from_below, double t_max_m) const {
    const double sign = from_below ? -1.0 : 1.0;
    const Distance f(*this, ray, offset_m, sign);
    // Bounds along the ray's horizontal direction of the ground's slope and of its curvature.
    double slope_along_ray = 0.0;
    double curvature_along_ray = 0.0;
    for (const auto& wave : waves_) {
        const double k = wave.wavenumber_rad_per_m.dot(ray.direction.head<2>());
        slope_along_ray += std::abs(wave.amplitude_m * k);
        curvature_along_ray += std::abs(wave.amplitude_m) * k * k;
    }
    // f can fall by at most `approach` per metre of ray.
    const double approach = slope_along_ray - sign * ray.direction.z();
    // The surface lies in the band [low, high] of sign * z; above `high` f > 0, below `low` f < 0.
    const double low = from_below ? -(max_height_m() + offset_m) : min_height_m() + offset_m;
    const double high = from_below ? -(min_height_m() + offset_m) : max_height_m() + offset_m;
    const double u0 = sign * ray.origin.z();
    const double du = sign * ray.direction.z();
    double t = 0.0;
    if (u0 > high) {
        if (du >= 0.0) return kNoHit;
        t = (u0 - high) / -du;
    }
    const double t_end = du < 0.0 ? std::min(t_max_m, (u0 - low) / -du) : t_max_m;
    if (t > t_end) return kNoHit;
    auto [value, slope] = f.ValueAndSlope(t);
    if (value <= 0.0) return t;
    if (approach <= 0.0) return kNoHit;  // the ray never comes closer to the surface
    for (int step = 0; step < kMaxSteps; ++step) {
        if (value < kTolerance_m) return t;
        // Two steps that cannot pass a crossing; take the longer. Linear: f falls at most
        // `approach` per metre. Quadratic: f(t + x) >= value + slope x - curvature x^2 / 2, whose
        // first root is Newton's step on flat ground and shrinks safely on curved ground.
        double safe = value / approach;
        if (curvature_along_ray > 0.0) {
            const double root = std::sqrt(slope * slope + 2.0 * curvature_along_ray * value);
            safe = std::max(safe, (slope + root) / curvature_along_ray);
        } else if (slope < 0.0) {
            safe = std::max(safe, value / -slope);
        }
        const double next = std::min(t + safe, t_end);
        const auto [next_value, next_slope] = f.ValueAndSlope(next);
        if (next_value <= 0.0) return Refine(f, t, value, next, next_value);
        if (next >= t_end) return kNoHit;
        t = next;
        value = next_value;
        slope = next_slope;
    }
    return kNoHit;
}

}  // namespace lidarloop::sim

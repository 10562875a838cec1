#include "lidarloop/core/scancontext/scancontext.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "lidarloop/core/detail/vector_clones.hpp"
#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

// Bound on the error of PolarCoordinates: 0.00151 rad measured over [0, 1] in float, plus the
// float rounding of the unfolding (< 1e-6 rad), rounded up.
constexpr double kAzimuthErrorRad = 0.002;

constexpr std::size_t kBatch = 256;  // points per pass of PolarCoordinates

// The planar ranges of points[0..count) (metres, in double) and their azimuths in sectors
// (azimuth * sectors / 2 pi, in [0, sectors]) to within kAzimuthErrorRad: atan on [0, 1] by the
// quadratic of Rajan et al. (IEEE Signal Processing Magazine 2006), unfolded to the full circle.
// Branch-free, so that it vectorises (the file is compiled without errno and trapping math);
// SectorBinner makes the sector exact. The origin reads 0; non-finite points give anything (the
// caller skips them).
LIDARLOOP_VECTOR_CLONES
void PolarCoordinates(const Eigen::Vector3f* points, std::size_t count, float per_radian,
                      double* ranges_m, float* positions) {
    for (std::size_t k = 0; k < count; ++k) {
        const float x = points[k].x();
        const float y = points[k].y();
        ranges_m[k] = std::sqrt(double{x} * x + double{y} * y);
        const float ax = std::abs(x);
        const float ay = std::abs(y);
        const float high = std::max(ax, ay);
        const float t = high > 0.0f ? std::min(ax, ay) / high : 0.0f;
        float a = 0.785398163f * t - t * (t - 1.0f) * (0.2447f + 0.0663f * t);
        a = ay > ax ? 1.570796327f - a : a;
        a = x < 0.0f ? 3.141592654f - a : a;
        a = y < 0.0f ? 6.283185307f - a : a;
        positions[k] = a * per_radian;
    }
}

// Sector indices of points, exact with respect to the sector borders: the approximate azimuth
// picks a sector; only when it lies within the approximation's error of a border, the signs of
// the cross products with the sector's two border directions decide, moving it by one when the
// point lies just across (sectors span less than 180 degrees).
class SectorBinner {
public:
    explicit SectorBinner(int sectors)
        : sectors_(sectors),
          per_radian_(static_cast<float>(sectors / (2.0 * std::numbers::pi))),
          margin_(static_cast<float>(kAzimuthErrorRad * sectors / (2.0 * std::numbers::pi))) {
        for (int j = 0; j <= sectors; ++j) {
            const double angle_rad = 2.0 * std::numbers::pi * j / sectors;
            border_x_.push_back(std::cos(angle_rad));
            border_y_.push_back(std::sin(angle_rad));
        }
    }

    float per_radian() const { return per_radian_; }

    // The sector of (x, y), not the origin, from its approximate `position` (PolarCoordinates).
    int Sector(float x, float y, float position) const {
        const int j = std::min(static_cast<int>(position), sectors_ - 1);
        const float within = position - static_cast<float>(j);
        if (within > margin_ && within < 1.0f - margin_) return j;  // clear of both borders
        if (Cross(j, x, y) < 0.0) return j == 0 ? sectors_ - 1 : j - 1;
        if (Cross(j + 1, x, y) >= 0.0) return j + 1 == sectors_ ? 0 : j + 1;
        return j;
    }

private:
    // > 0 when (x, y) lies counter-clockwise of border j.
    double Cross(int j, float x, float y) const {
        return border_x_[static_cast<std::size_t>(j)] * y -
               border_y_[static_cast<std::size_t>(j)] * x;
    }

    int sectors_;
    float per_radian_;
    float margin_;  // kAzimuthErrorRad in sectors
    std::vector<double> border_x_;
    std::vector<double> border_y_;
};

}  // namespace

std::vector<float> RingKey(const std::vector<float>& bins, int rings, int sectors) {
    std::vector<float> key(static_cast<std::size_t>(rings), 0.0f);
    for (int i = 0; i < rings; ++i) {
        const auto row = bins.begin() + static_cast<std::ptrdiff_t>(i) * sectors;
        const auto occupied = std::count_if(row, row + sectors, [](float v) { return v != 0.0f; });
        key[static_cast<std::size_t>(i)] =
            static_cast<float>(occupied) / static_cast<float>(sectors);
    }
    return key;
}

ScanContext ComputeScanContext(PointsView points, const ScanContextConfig& config) {
    config.Validate();
    ScanContext sc;
    sc.rings = config.rings;
    sc.sectors = config.sectors;
    sc.bins.assign(static_cast<std::size_t>(config.rings) * config.sectors, 0.0f);
    const SectorBinner binner(config.sectors);
    const double rings_per_m = config.rings / config.max_range_m;
    const auto offset_m = static_cast<float>(config.sensor_height_m);
    std::array<double, kBatch> ranges_m;
    std::array<float, kBatch> positions;
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (i % kBatch == 0) {  // the next batch's azimuths at once, vectorised
            PolarCoordinates(points.data() + i, std::min(kBatch, points.size() - i),
                             binner.per_radian(), ranges_m.data(), positions.data());
        }
        const Eigen::Vector3f& p = points[i];
        if (!p.allFinite()) {
            ++sc.points_skipped;
            continue;
        }
        const double range_m = ranges_m[i % kBatch];
        if (range_m >= config.max_range_m) {
            ++sc.points_out_of_range;
            continue;
        }
        ++sc.points_used;
        const int ring = std::min(static_cast<int>(range_m * rings_per_m), config.rings - 1);
        const int sector = range_m > 0.0 ? binner.Sector(p.x(), p.y(), positions[i % kBatch]) : 0;
        float& bin = sc.bins[static_cast<std::size_t>(ring) * config.sectors + sector];
        bin = std::max(bin, p.z() + offset_m);  // bins start at 0: heights below it read 0
    }
    if (sc.points_used == 0) {
        throw EmptyInputError("scancontext: no finite point within scancontext.max_range_m (" +
                              std::to_string(points.size()) + " points given)");
    }
    sc.ring_key = RingKey(sc.bins, sc.rings, sc.sectors);
    return sc;
}

}  // namespace lidarloop::core

#include "lidarloop/core/scancontext/scancontext.hpp"

#include <algorithm>
#include <cmath>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The azimuth of (x, y) in [0, 2 pi) to within 0.0015 rad: atan on [0, 1] by the quadratic of
// Rajan et al. (IEEE Signal Processing Magazine 2006), unfolded to the full circle. Four times
// cheaper than std::atan2; SectorBinner makes the sector exact afterwards.
float ApproximateAzimuth(float x, float y) {
    const float ax = std::abs(x);
    const float ay = std::abs(y);
    const float t = std::min(ax, ay) / std::max(ax, ay);  // caller excludes x = y = 0
    float a = 0.785398163f * t - t * (t - 1.0f) * (0.2447f + 0.0663f * t);
    if (ay > ax) a = 1.570796327f - a;
    if (x < 0.0f) a = 3.141592654f - a;
    if (y < 0.0f) a = 6.283185307f - a;
    return a;
}

// Polar bin indices of points, exact with respect to the sector borders: the approximate
// azimuth picks a sector, the signs of the cross products with its two border directions move it
// by one when the point lies just across a border (sectors span less than 180 degrees).
class SectorBinner {
public:
    explicit SectorBinner(int sectors)
        : sectors_(sectors), per_radian_(static_cast<float>(sectors / (2.0 * kPi))) {
        for (int j = 0; j <= sectors; ++j) {
            const double angle_rad = 2.0 * kPi * j / sectors;
            border_x_.push_back(std::cos(angle_rad));
            border_y_.push_back(std::sin(angle_rad));
        }
    }

    // The sector of (x, y), which is not the origin.
    int Sector(float x, float y) const {
        int j = std::min(static_cast<int>(ApproximateAzimuth(x, y) * per_radian_), sectors_ - 1);
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
    const double max_range_sq = config.max_range_m * config.max_range_m;
    const double rings_per_m = config.rings / config.max_range_m;
    const auto offset_m = static_cast<float>(config.sensor_height_m);
    for (const Eigen::Vector3f& p : points) {
        if (!p.allFinite()) {
            ++sc.points_skipped;
            continue;
        }
        const double range_sq = double{p.x()} * p.x() + double{p.y()} * p.y();
        if (range_sq >= max_range_sq) {
            ++sc.points_out_of_range;
            continue;
        }
        ++sc.points_used;
        const int ring =
            std::min(static_cast<int>(std::sqrt(range_sq) * rings_per_m), config.rings - 1);
        const int sector = range_sq > 0.0 ? binner.Sector(p.x(), p.y()) : 0;
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

#include "lidarloop/core/ndt/sphere_partition.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <sstream>
#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

constexpr double kHalfPi = std::numbers::pi / 2.0;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr int kMaxRegions = 10000;

// Area of the polar cap of the given colatitude on the unit sphere, 2*pi*(1 - cos theta), written
// with sin^2(theta/2) so that small caps keep their relative accuracy.
double CapArea(double colatitude) {
    const double s = std::sin(colatitude / 2.0);
    return 4.0 * std::numbers::pi * s * s;
}

// Colatitude of the polar cap that holds `cumulative` of the n equal regions of the half sphere:
// 2*pi*(1 - cos theta) = cumulative * 2*pi/n, i.e. sin(theta/2) = sqrt(cumulative / (2n)).
// Leopardi 2006, section 3: zone boundaries come from cumulative equal areas, not from the ideal
// collar angles, so every region has exactly the area 2*pi/n.
double CapColatitude(int cumulative, int n) {
    if (cumulative >= n) return kHalfPi;  // exactly the equator, not asin's rounding of it
    return 2.0 * std::asin(std::sqrt(static_cast<double>(cumulative) / (2.0 * n)));
}

// Number of regions in each zone: the polar cap, then the collars down to the equator.
// Leopardi 2006, section 3, with the bottom polar cap removed and the span between the polar cap
// and the equator (pi/2 - theta_c) in place of the span between the two caps (pi - 2 theta_c).
std::vector<int> ZoneRegionCounts(int n) {
    if (n == 1) return {1};  // the polar cap is the whole half sphere
    const double region_area = kTwoPi / n;
    const double polar_colatitude = CapColatitude(1, n);
    // The ideal collar angle is the side of a square of the region's area, V_R^(1/d) with d = 2,
    // so that regions come out close to square; the number of collars rounds the ideal count.
    const double ideal_angle = std::sqrt(region_area);
    const double span = kHalfPi - polar_colatitude;
    const int collars = std::max(1, static_cast<int>(std::lround(span / ideal_angle)));
    const double fitting_angle = span / collars;
    std::vector<int> counts = {1};
    int assigned = 1;
    double discrepancy = 0.0;  // Leopardi's a_i: sum of (ideal - rounded) over earlier collars
    for (int i = 0; i < collars; ++i) {
        const double top = polar_colatitude + i * fitting_angle;
        const double bottom = (i + 1 == collars) ? kHalfPi : top + fitting_angle;
        const double ideal = (CapArea(bottom) - CapArea(top)) / region_area;
        int count = static_cast<int>(std::lround(ideal + discrepancy));
        // The ideal counts sum to n - 1 and |discrepancy| <= 1/2, so the last rounding gives
        // exactly the regions left; take them so that round-off cannot lose or add one.
        if (i + 1 == collars) count = n - assigned;
        discrepancy += ideal - count;
        counts.push_back(count);
        assigned += count;
    }
    return counts;
}

// Longitude shift, in turns, of the collar below one with `top` sectors when it has `bottom`
// sectors (Leopardi's EQSP toolbox, circle_offset, without its optional extra twist). The first
// term cancels the half-sector positions of the two collars' centres, whose longitudes then
// differ by multiples of gcd(top, bottom)/(top*bottom) turns; the second adds half that step,
// which staggers the centres of adjacent collars as far apart as possible. Areas are unaffected.
double NextCollarOffset(int top, int bottom) {
    return (1.0 / bottom - 1.0 / top) / 2.0 +
           std::gcd(top, bottom) / (2.0 * static_cast<double>(top) * bottom);
}

Eigen::Vector3d UnitVector(double colatitude, double longitude) {
    const double s = std::sin(colatitude);
    return {s * std::cos(longitude), s * std::sin(longitude), std::cos(colatitude)};
}

// True when `d` is the lower-half representative of its line: z < 0, or on the equator the one
// with y < 0, or on the x axis the one with x < 0. Negation is exact, so d and -d always yield
// the same upper representative.
bool IsLowerRepresentative(const Eigen::Vector3d& d) {
    if (d.z() != 0.0) return d.z() < 0.0;
    if (d.y() != 0.0) return d.y() < 0.0;
    return d.x() < 0.0;
}

}  // namespace

HalfSpherePartition::HalfSpherePartition(int regions) {
    if (regions < 1 || regions > kMaxRegions) {
        throw ConfigError("HalfSpherePartition: the number of regions must be in [1, " +
                          std::to_string(kMaxRegions) + "], got " + std::to_string(regions));
    }
    const int n = regions;
    zone_region_counts_ = ZoneRegionCounts(n);
    const std::size_t zones = zone_region_counts_.size();
    zone_colatitudes_.assign(1, 0.0);
    int cumulative = 0;
    double offset_turns = 0.0;
    centres_.reserve(static_cast<std::size_t>(n));
    regions_.reserve(static_cast<std::size_t>(n));
    for (std::size_t zone = 0; zone < zones; ++zone) {
        const int count = zone_region_counts_[zone];
        const double top = zone_colatitudes_.back();
        zone_first_region_.push_back(cumulative);
        cumulative += count;
        const double bottom = CapColatitude(cumulative, n);
        zone_colatitudes_.push_back(bottom);
        zone_min_z_.push_back(static_cast<double>(n - cumulative) / n);  // cos(bottom), exact 0
        if (zone == 0) {
            zone_offset_turns_.push_back(0.0);
            regions_.push_back({0, top, bottom, 0.0, kTwoPi});
            centres_.push_back(Eigen::Vector3d::UnitZ());  // the centre of a cap is its pole
            continue;
        }
        zone_offset_turns_.push_back(offset_turns);
        const double sector_turns = 1.0 / count;
        for (int j = 0; j < count; ++j) {
            double start_turns = offset_turns + j * sector_turns;
            start_turns -= std::floor(start_turns);
            const double start = kTwoPi * start_turns;
            const double end = start + kTwoPi * sector_turns;
            regions_.push_back({static_cast<int>(zone), top, bottom, start, end});
            // Leopardi's EQ point: the middle of the colatitude and longitude intervals; a ring
            // (one sector, n = 2 only) takes its start longitude, as in the EQSP toolbox.
            const double longitude = count == 1 ? start : (start + end) / 2.0;
            centres_.push_back(UnitVector((top + bottom) / 2.0, longitude));
        }
        if (zone + 1 < zones) {
            offset_turns += NextCollarOffset(count, zone_region_counts_[zone + 1]);
            offset_turns -= std::floor(offset_turns);
        }
    }
}

int HalfSpherePartition::RegionOf(const Eigen::Vector3d& direction) const {
    // Scale by the largest coordinate first so that the norm neither overflows nor underflows.
    const double scale = direction.cwiseAbs().maxCoeff();
    if (!(scale > 0.0) || !std::isfinite(scale)) {
        std::ostringstream message;
        message << "HalfSpherePartition::RegionOf: the direction must be finite and non-zero, got ("
                << direction.x() << ", " << direction.y() << ", " << direction.z() << ")";
        throw Error(message.str());
    }
    const Eigen::Vector3d d =
        IsLowerRepresentative(direction) ? Eigen::Vector3d(-direction) : direction;
    const Eigen::Vector3d u = d / scale;
    const double z = u.z() / u.norm();
    std::size_t zone = 0;
    while (zone + 1 < zone_min_z_.size() && z < zone_min_z_[zone]) ++zone;
    const int count = zone_region_counts_[zone];
    if (count == 1) return zone_first_region_[zone];
    double turns = std::atan2(d.y(), d.x()) / kTwoPi - zone_offset_turns_[zone];
    turns -= std::floor(turns);
    // turns is in [0, 1]; it can round up to 1 just below the start of sector 0.
    const int sector = std::min(count - 1, static_cast<int>(turns * count));
    return zone_first_region_[zone] + sector;
}

int HalfSpherePartition::NearestLine(const Eigen::Vector3d& direction) const {
    // Magnusson eq. (2): the distance from e to the line through c_j (|c_j| = 1) is
    // sqrt(|e|^2 - (e . c_j)^2), smallest where |e . c_j| is largest.
    int best = 0;
    double best_dot = -1.0;
    const std::size_t n = centres_.size();
    for (std::size_t j = 0; j < n; ++j) {
        const double dot = std::abs(direction.dot(centres_[j]));
        if (dot > best_dot) {  // strict: ties keep the lowest index
            best_dot = dot;
            best = static_cast<int>(j);
        }
    }
    return best;
}

}  // namespace lidarloop::core

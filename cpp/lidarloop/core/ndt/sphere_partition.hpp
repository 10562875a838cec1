#pragma once

#include <vector>

#include <Eigen/Core>

namespace lidarloop::core {

/// One region of a HalfSpherePartition in spherical polar coordinates, radians. Colatitude is
/// measured from +z, longitude counter-clockwise about +z from +x. The region holds the unit
/// vectors with colatitude in [colatitude_min, colatitude_max] and longitude in
/// [longitude_min, longitude_max] modulo 2*pi; longitude_min lies in [0, 2*pi) and longitude_max
/// may exceed 2*pi. The polar cap spans longitudes [0, 2*pi].
struct SphereRegion {
    int zone = 0;                 ///< 0 = polar cap, 1.. = collars from the pole to the equator
    double colatitude_min = 0.0;  ///< radians, in [0, pi/2]
    double colatitude_max = 0.0;  ///< radians, in [0, pi/2]
    double longitude_min = 0.0;   ///< radians, in [0, 2*pi)
    double longitude_max = 0.0;  ///< radians, longitude_min < longitude_max <= longitude_min + 2*pi
};

/// An equal-area partition of the upper half sphere into `regions` cells (Leopardi's EQ
/// construction restricted to z >= 0); lines through the origin are identified with their
/// upper-half point. Magnusson et al. 2009, section II-B, sub-class planar and linear NDT cells by
/// the lines through the centres of such a partition (p = 9 in the paper).
///
/// Zones: zone 0 is a polar cap of area 2*pi/n around +z; zones 1.. are collars (bands between two
/// colatitudes) down to the equator, each split by longitude into equal sectors. Regions are
/// numbered zone by zone from the pole, and by increasing longitude from the zone's offset within
/// a zone. Immutable after construction, so every member is safe to call from many threads.
class HalfSpherePartition {
public:
    /// Builds the partition into `regions` cells, 1..10000. Throws ConfigError otherwise.
    explicit HalfSpherePartition(int regions);

    /// n, the number of regions.
    int size() const { return static_cast<int>(centres_.size()); }

    /// The centre of each region, a unit vector with z > 0 (z = 1 for the polar cap): the middle
    /// colatitude and the middle longitude of the region, as in Leopardi's EQ point set. The line
    /// P_j of Magnusson eq. (2) passes through the origin and centres()[j].
    const std::vector<Eigen::Vector3d>& centres() const { return centres_; }

    /// The bounds of every region, indexed like centres().
    const std::vector<SphereRegion>& regions() const { return regions_; }

    /// Zone boundaries, radians: zone k spans colatitudes [zone_colatitudes()[k],
    /// zone_colatitudes()[k + 1]]; the first value is 0 and the last exactly pi/2.
    const std::vector<double>& zone_colatitudes() const { return zone_colatitudes_; }

    /// Number of regions in each zone: 1 for the polar cap, then one count per collar; sums to n.
    const std::vector<int>& zone_region_counts() const { return zone_region_counts_; }

    /// The region that contains the line through the origin along `direction` (any finite,
    /// non-zero length). The direction is first replaced by whichever of +direction and
    /// -direction lies in the closed upper half space, so RegionOf(d) == RegionOf(-d). On the
    /// equator (z == 0) both qualify; the one with y > 0, or with y == 0 and x > 0, is used.
    /// Points on a boundary go to the zone nearer the pole and to the sector that starts there.
    /// Throws Error for a zero or non-finite direction. O(zones), no allocation.
    int RegionOf(const Eigen::Vector3d& direction) const;

    /// Magnusson eq. (2): the index j of the line P_j nearest to `direction`, that is
    /// argmax_j |direction . centres()[j]| (the distance from a unit e to P_j is
    /// sqrt(1 - (e . c_j)^2)); ties go to the lowest index. Any non-zero length; a zero or NaN
    /// direction gives 0. This is the Voronoi cell of the lines, not RegionOf: the two differ near
    /// region boundaries. O(n), no allocation, no exception; meant for hot loops.
    int NearestLine(const Eigen::Vector3d& direction) const;

private:
    std::vector<Eigen::Vector3d> centres_;
    std::vector<SphereRegion> regions_;
    std::vector<double> zone_colatitudes_;
    std::vector<int> zone_region_counts_;
    std::vector<int> zone_first_region_;     // index of the first region of each zone
    std::vector<double> zone_min_z_;         // cos of the largest colatitude of each zone
    std::vector<double> zone_offset_turns_;  // longitude where sector 0 starts, in turns [0, 1)
};

}  // namespace lidarloop::core

#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/core/voxel_grid.hpp"

namespace lidarloop::core {

/// How a map of placed scans is reduced (YAML section `map`; `lidarloop map --voxel`).
struct MapConfig {
    /// Edge of the voxels the placed points are averaged into, metres, [0.01, 100].
    double voxel_m = 0.2;
    /// Most points (voxels) a map holds, [1000, 1e8]. A map that would hold more has its voxel
    /// edge doubled until it fits (VoxelGrid::Coarsen), so memory stays bounded whatever the
    /// sequence: 70 to 150 bytes a voxel while building, 23 or 35 bytes a point in the PLY.
    std::size_t max_points = 2'000'000;

    /// Throws core::ConfigError naming the field ("map.voxel_m must be ...").
    void Validate() const;
    bool operator==(const MapConfig&) const = default;
};

/// One point of a map: a voxel centroid in the world frame and the mean time of the scans its
/// points came from.
struct MapPoint {
    Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< metres, world frame
    double time_s = 0.0;                                 ///< mean scan time, seconds
};

/// A map built by PointMap.
struct MapCloud {
    std::vector<MapPoint> points;  ///< in the order of their voxels' first point
    double voxel_m = 0.0;          ///< the voxel edge used (config.voxel_m, or coarser)
    std::size_t scans = 0;         ///< scans added
    std::size_t input_points = 0;  ///< finite points added
    /// Times of the earliest and latest scan added (NaN when none): the ends of the colour scale.
    double first_time_s = std::numeric_limits<double>::quiet_NaN();
    double last_time_s = std::numeric_limits<double>::quiet_NaN();
};

/// Scans placed with their poses and averaged into voxels, a scan at a time: the scans need not
/// be held (read, add, drop). Deterministic for a given order of scans. Not thread-safe for
/// writing; distinct maps may be filled from distinct threads.
class PointMap {
public:
    /// Throws core::ConfigError for an invalid `config`.
    explicit PointMap(const MapConfig& config);

    /// Adds the finite points of `scan` (sensor frame, metres) placed with `T_world_scan`, each
    /// carrying `time_s`; non-finite points are skipped. When the map then holds more than
    /// config.max_points voxels, the voxel edge doubles until it does not. Throws core::Error
    /// for a non-finite pose or time.
    void AddScan(PointsView scan, const Transform& T_world_scan, double time_s);

    double voxel_m() const { return grid_.voxel_m(); }
    std::size_t size() const { return grid_.size(); }
    /// The map's points and what it was built from.
    MapCloud Cloud() const;

private:
    MapConfig config_;
    VoxelGrid grid_;
    std::vector<Eigen::Vector3d> placed_;  // the scan being added, in the world frame
    std::size_t scans_ = 0;
    std::size_t input_points_ = 0;
    double first_time_s_ = std::numeric_limits<double>::quiet_NaN();
    double last_time_s_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace lidarloop::core

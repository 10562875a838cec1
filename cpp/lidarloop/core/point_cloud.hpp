#pragma once

#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace lidarloop::core {

/// One LiDAR scan: points in the sensor frame (origin at the sensor), metres, x forward, y left,
/// z up (right-handed). Points may be non-finite (no return); consumers skip and count them.
using PointCloud = std::vector<Eigen::Vector3f>;

/// Points in the same layout without owning them (a PointCloud converts implicitly), e.g. the
/// memory of a NumPy array, so that a caller need not copy them into a PointCloud.
using PointsView = std::span<const Eigen::Vector3f>;

/// A rigid transform T_target_source: maps coordinates in the source frame into the target frame.
using Transform = Eigen::Isometry3d;

/// A ground-truth or odometry pose of a scan: T_world_sensor, world in metres, time in seconds.
struct StampedPose {
    double time_s = 0.0;
    Transform T_world_sensor = Transform::Identity();
    /// Metres travelled since the trajectory's first pose, when the poses are some of a longer
    /// trajectory's (frames of a KITTI sequence); else unset: the steps between them are the path.
    std::optional<double> path_m;
};

}  // namespace lidarloop::core

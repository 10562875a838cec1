#pragma once

#include <cstdint>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::sim {

/// What a LiDAR-inertial odometry front end keeps of each scan before it stores a keyframe:
/// real keyframe sequences are thinned (FAST-LIO-style front ends keep every N-th point of a
/// scan), and loop closure must work on them.
struct FrontEndConfig {
    /// Keep every N-th returned point of each scan in the sensor's emission order (the first,
    /// the N+1-th, ...), 1-1000; 1 keeps all. Lost returns (nothing hit, dropouts) are not
    /// points, so they do not count.
    std::int64_t keep_every = 1;

    /// Throws core::ConfigError naming the field ("front_end.keep_every ...").
    void Validate() const;
};

/// Points 0, n, 2n, ... of `cloud` (n >= 1), in their order.
core::PointCloud KeepEvery(const core::PointCloud& cloud, std::int64_t n);

}  // namespace lidarloop::sim

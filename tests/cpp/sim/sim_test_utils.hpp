#pragma once

#include <cstring>

#include <Eigen/Core>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/sim/sensor.hpp"
#include "lidarloop/sim/shapes.hpp"

// Helpers that several simulator tests share.
namespace lidarloop::sim {

inline SensorSpec SpecOf(SensorModel model) {
    SensorConfig config;
    config.model = model;
    return Resolve(config);
}

inline bool SameBytes(const core::PointCloud& a, const core::PointCloud& b) {
    return a.size() == b.size() &&
           std::memcmp(a.data(), b.data(), a.size() * sizeof(Eigen::Vector3f)) == 0;
}

inline Ray MakeRay(Eigen::Vector3d origin, Eigen::Vector3d direction) {
    return {origin, direction.normalized()};
}

}  // namespace lidarloop::sim

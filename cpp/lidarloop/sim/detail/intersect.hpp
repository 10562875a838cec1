#pragma once

// Internal: the ray-box test with the yaw's cosine and sine given, so that the world's hot loop
// does not evaluate trigonometric functions per ray. Not installed.

#include "lidarloop/sim/shapes.hpp"

namespace lidarloop::sim::detail {

/// Intersect(ray, box) with cos(box.yaw_rad) and sin(box.yaw_rad) precomputed.
double IntersectBox(const Ray& ray, const Box& box, double cos_yaw, double sin_yaw);

}  // namespace lidarloop::sim::detail

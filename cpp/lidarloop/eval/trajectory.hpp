#pragma once

#include <cstddef>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::eval {

/// The rigid transform (rotation and translation, no scale) that best aligns `estimate`'s
/// positions onto `truth`'s in the least-squares sense: argmin over T of
/// sum_i |truth_i - T * estimate_i|^2, in closed form (Umeyama 1991 with the scale fixed to 1,
/// i.e. Horn's absolute orientation by SVD, with the reflection guard). T maps the estimate's
/// world frame into the truth's. Needs equal sizes (core::ConfigError otherwise); with fewer
/// than 3 points or collinear points the rotation is not unique and any minimiser may be given.
core::Transform AlignRigid(const std::vector<Eigen::Vector3d>& estimate,
                           const std::vector<Eigen::Vector3d>& truth);

/// Absolute trajectory error: the RMSE (metres) of the positions of `estimate`, aligned onto
/// `truth` by AlignRigid, against the positions of `truth` (pose i against pose i). Rotations are
/// not compared. core::ConfigError when the sizes differ or are 0.
double AbsoluteTrajectoryRmse(const std::vector<core::Transform>& estimate,
                              const std::vector<core::Transform>& truth);

/// Relative pose error as the KITTI odometry benchmark computes it.
struct TrajectoryRpe {
    double translation_percent = 0.0;    ///< mean |t(E)| / L, times 100
    double rotation_deg_per_100m = 0.0;  ///< mean angle(E) / L, degrees per 100 m
    std::size_t segments = 0;            ///< pairs averaged; 0: none long enough (values NaN)
};

/// Which segments RPE averages: from every `step`-th pose i, for every length L, the first
/// pose j whose ground-truth path length from i is at least L.
struct TrajectoryRpeConfig {
    std::vector<double> lengths_m = {100, 200, 300, 400, 500, 600, 700, 800};
    std::size_t step = 10;
};

/// KITTI-style RPE: for each segment (i, j) of TrajectoryRpeConfig, the error
/// E = (truth_i^-1 truth_j)^-1 (estimate_i^-1 estimate_j); its translation norm and rotation
/// angle are divided by L and averaged over all segments of all lengths (Geiger et al. 2012,
/// the devkit's evaluate_odometry). No alignment is needed: E is frame independent.
/// core::ConfigError when the sizes differ, the step is 0 or a length is not positive.
TrajectoryRpe ComputeTrajectoryRpe(const std::vector<core::Transform>& estimate,
                                   const std::vector<core::Transform>& truth,
                                   const TrajectoryRpeConfig& config = {});

}  // namespace lidarloop::eval

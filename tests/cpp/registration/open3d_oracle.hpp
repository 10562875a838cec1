#pragma once

// The field's registration, as a test and benchmark oracle: Open3D's global registration of two
// scans without a prior pose (voxel grid, normals, FPFH features, RANSAC on mutual feature
// matches), refined by ICP. Only tests and benchmarks link it; it exists when CMake found Open3D:
// if(TARGET lidarloop::open3d_oracle), see cmake/LidarloopOpen3dOracle.cmake.

#include <cstddef>
#include <cstdint>

#include <Eigen/Geometry>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::test {

/// The local registration that refines RANSAC's pose.
enum class Open3dRefinement {
    kPointToPlane,    ///< point-to-plane ICP (normals of the match scan)
    kGeneralizedIcp,  ///< generalized ICP (Segal et al., RSS 2009), plane-to-plane
};

/// Parameters of RegisterWithOpen3d. The defaults are for outdoor spinning LiDAR (KITTI
/// HDL-64E, 120k points, range to 80 m); distances are metres.
struct Open3dOracleConfig {
    double min_range_m = 2.5;        ///< drop points closer to the sensor (returns from the car)
    double max_range_m = 60.0;       ///< drop points farther (sparse, noisy features); 0: keep all
    double voxel_m = 0.75;           ///< voxel grid of the global registration, (0.05, 5]
    double normal_radius_m = 1.5;    ///< neighbourhood of a normal (Open3D tutorial: 2 voxels)
    int normal_max_neighbours = 30;  ///< at most that many neighbours per normal
    double feature_radius_m = 3.75;  ///< FPFH neighbourhood (Open3D tutorial: 5 voxels)
    int feature_max_neighbours = 100;     ///< at most that many neighbours per FPFH
    double ransac_distance_m = 1.125;     ///< inlier distance of RANSAC (tutorial: 1.5 voxels)
    double edge_length_similarity = 0.9;  ///< edge length checker: min ratio of sample edges
    int ransac_max_iterations = 100000;   ///< RANSAC stops here at the latest
    double ransac_confidence = 0.999;     ///< or earlier, at this confidence, in (0, 1]
    Open3dRefinement refinement = Open3dRefinement::kGeneralizedIcp;
    double refine_voxel_m = 0.25;    ///< voxel grid of the refinement, (0.01, voxel_m]
    double refine_distance_m = 1.0;  ///< ICP correspondence distance
    int refine_max_iterations = 60;  ///< ICP stops here at the latest
    std::uint32_t seed = 42;         ///< seeds Open3D's global random engine at every call

    /// Throws core::ConfigError naming the first field out of its range.
    void Validate() const;
};

/// Seconds spent in each stage of RegisterWithOpen3d (wall clock).
struct Open3dStageTimes {
    double features_s = 0.0;  ///< range filter, voxel grids, normals and FPFH of both scans
    double ransac_s = 0.0;    ///< mutual feature matching and RANSAC
    double refine_s = 0.0;    ///< ICP
};

/// Open3D's registration of a query scan to a match scan.
struct Open3dRegistration {
    /// Maps query points into the match frame (the relative pose of the query in the match's
    /// sensor frame).
    Eigen::Isometry3d T_match_query = Eigen::Isometry3d::Identity();
    /// Open3D's fitness of the refinement: the fraction of the query's refinement-grid points
    /// that have a match point within refine_distance_m at T_match_query, [0, 1]. On KITTI
    /// (docs/BENCHMARK.md): 0.92-0.99 for true pairs, 0.56 for scans of different places (the
    /// road alone brings half of the points within 1 m).
    double fitness = 0.0;
    double rmse_m = 0.0;  ///< Open3D's inlier RMSE of those point pairs, metres
    /// Fitness of RANSAC's best pose (Open3D 0.16 scores hypotheses like ICP): the fraction of
    /// the query's global-grid points with a match point within ransac_distance_m, [0, 1].
    double ransac_fitness = 0.0;
    std::size_t ransac_inliers = 0;  ///< how many query points those are
    std::size_t query_points = 0;    ///< query points on the global registration's voxel grid
    std::size_t match_points = 0;    ///< match points on the global registration's voxel grid
    Open3dStageTimes times;
};

/// Registers `query` to `match` (points in each scan's sensor frame, metres; non-finite points
/// are skipped) with Open3D, without a prior pose. Repeatable: the same input and config give the
/// same pose (up to the last bits: ICP sums its point pairs in thread order), since Open3D's
/// global random engine is seeded with config.seed and RANSAC runs on one thread (with more, the
/// threads' draws from the shared engine interleave by timing); features and ICP use OpenMP's
/// threads. Not thread-safe: Open3D's random engine is process-wide. Throws core::ConfigError for
/// an invalid config and core::EmptyInputError when a scan keeps fewer than 3 points after
/// filtering.
Open3dRegistration RegisterWithOpen3d(const core::PointCloud& query, const core::PointCloud& match,
                                      const Open3dOracleConfig& config = {});

}  // namespace lidarloop::test

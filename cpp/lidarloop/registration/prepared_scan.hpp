#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/registration/neighbor_grid.hpp"
#include "lidarloop/registration/verification_config.hpp"

namespace lidarloop::registration {

/// Points of one surface class of a reduced scan, with unit normals and a neighbour search.
/// Immutable; neither copyable nor movable, so held by pointer.
class SurfacePoints {
public:
    /// `normals[i]` belongs to `points[i]`; both in the sensor frame, metres.
    SurfacePoints(std::vector<Eigen::Vector3f> points, std::vector<Eigen::Vector3f> normals);
    SurfacePoints(const SurfacePoints&) = delete;
    SurfacePoints& operator=(const SurfacePoints&) = delete;

    const std::vector<Eigen::Vector3f>& points() const { return points_; }
    const std::vector<Eigen::Vector3f>& normals() const { return normals_; }
    /// The exact nearest-neighbour search over points(), by their indices.
    const NeighborGrid& grid() const { return grid_; }
    std::size_t size() const { return points_.size(); }
    /// Heap bytes held: points, normals and the search grid.
    std::size_t MemoryBytes() const;

private:
    void shrink();  // before the grid is built: MemoryBytes counts capacity

    std::vector<Eigen::Vector3f> points_;
    std::vector<Eigen::Vector3f> normals_;
    NeighborGrid grid_;
};

/// What registration keeps of a scan: voxel centroids with normals, split into structure
/// (normals far from vertical: what tells places apart) and ground (the rest). A few thousand
/// points instead of a raw scan's ~120k; cheap to copy (shared, immutable parts).
struct PreparedScan {
    std::shared_ptr<const SurfacePoints> structure;
    std::shared_ptr<const SurfacePoints> ground;
    std::size_t input_points = 0;   ///< points of the raw scan
    std::size_t usable_points = 0;  ///< finite points within the range limits
    /// How well the scan fits itself, metres: the RMS distance of its structure points (within
    /// 40 m; at most 1000 of them, an even stride) to the planes of their 4 nearest other
    /// structure points, each pair counted as the overlap test counts one (partner within 1.5 m,
    /// normals within 30 degrees, plane within 0.3 m: the AcceptanceConfig defaults). It is the
    /// residual a right registration leaves between two scans of this density, noise and
    /// surface kind (sparse rings, vegetation, de-skewing); a pair's RMSE is judged against it
    /// (AcceptanceConfig::max_rmse_ratio). 0 without pairs.
    double structure_roughness_m = 0.0;
    /// Per structure point: 1 when it is distinctive, i.e. not part of a large plane (a wall, a
    /// facade) at the scale of distinctive_neighbors voxels; poles, trunks, cars, door leaves,
    /// corners. Walls look alike in every street and corridor; these tell places apart.
    std::vector<std::uint8_t> structure_distinctive;
    /// Where the scan looks (ViewCentre of the raw scan; a submap keeps its centre scan's): the
    /// odometry orders a query's candidates by it (pipeline::LoopCheck::view_distance_m).
    Eigen::Vector3d view_centre =
        Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());

    /// Heap bytes held by the prepared scan (the figure bench reports per stored scan).
    std::size_t MemoryBytes() const;
};

/// Reduces `scan` (sensor frame, metres) for registration: range filter, voxel centroids, normals
/// from the nearest centroids, split by normal tilt, and a deterministic subsample to the size
/// caps. Never throws on bad points: non-finite ones are skipped, and a scan with too little
/// left gives an almost empty result that Verify rejects with the reason. Thread-safe.
PreparedScan PrepareScan(const core::PointCloud& scan, const ScanReductionConfig& config);

/// Where `scan` looks: the mean of its usable points (finite, within the range limits of
/// `config`), sensor frame, metres; NaN without any. Near the sensor for a 360-degree scan, ahead
/// of it for a narrow field of view.
Eigen::Vector3d ViewCentre(const core::PointCloud& scan, const ScanReductionConfig& config);

}  // namespace lidarloop::registration

#pragma once

#include <string>
#include <string_view>

#include <Eigen/Core>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::core {

/// Point projection functions v: R^3 -> R of Röhling et al. 2015, section III-B.
enum class Projection {
    kHeight,  ///< v(p) = <p, u> + sensor height: height above the ground plane
    kRange,   ///< v(p) = ||p||: distance from the sensor origin
};

/// Where the up vector u of the height projection comes from.
enum class UpVectorMode {
    kFixed,  ///< u = (0, 0, 1): the sensor's z axis
    kPca,    ///< normal of the dominant plane by PCA of the scan, oriented so that u_z >= 0
};

std::string ToString(Projection projection);
std::string ToString(UpVectorMode mode);
/// Parse "height"/"range" and "fixed"/"pca"; throw ConfigError listing the valid names.
Projection ParseProjection(std::string_view name);
UpVectorMode ParseUpVectorMode(std::string_view name);

/// Up vector by PCA (Röhling III-B): the eigenvector of the smallest eigenvalue of the covariance
/// of the finite points, the direction of least spread, which for a ground vehicle's scan is the
/// normal of the ground. Sign chosen so that z >= 0 ("positive z values point upwards").
/// Throws EmptyInputError with fewer than 3 finite points, or points that span no plane
/// (identical, or on one line).
Eigen::Vector3d EstimateUpVectorPca(PointsView cloud);
/// The same for a PointCloud (or a braced list of points).
inline Eigen::Vector3d EstimateUpVectorPca(const PointCloud& cloud) {
    return EstimateUpVectorPca(PointsView(cloud));
}

}  // namespace lidarloop::core

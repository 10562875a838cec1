#include "lidarloop/core/projection.hpp"

#include <Eigen/Eigenvalues>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {

std::string ToString(Projection projection) {
    return projection == Projection::kHeight ? "height" : "range";
}

std::string ToString(UpVectorMode mode) { return mode == UpVectorMode::kFixed ? "fixed" : "pca"; }

Projection ParseProjection(std::string_view name) {
    if (name == "height") return Projection::kHeight;
    if (name == "range") return Projection::kRange;
    throw ConfigError("unknown projection '" + std::string(name) + "' (valid: height, range)");
}

UpVectorMode ParseUpVectorMode(std::string_view name) {
    if (name == "fixed") return UpVectorMode::kFixed;
    if (name == "pca") return UpVectorMode::kPca;
    throw ConfigError("unknown up vector mode '" + std::string(name) + "' (valid: fixed, pca)");
}

Eigen::Vector3d EstimateUpVectorPca(const PointCloud& cloud) {
    // Two passes (mean, then centred second moments) keep the covariance accurate for scans far
    // from the origin, which a one-pass sum of squares would not.
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t finite_count = 0;
    for (const auto& p : cloud) {
        if (!p.allFinite()) continue;
        sum += p.cast<double>();
        ++finite_count;
    }
    if (finite_count < 3) {
        throw EmptyInputError("PCA up vector needs at least 3 finite points, the scan has " +
                              std::to_string(finite_count));
    }
    const Eigen::Vector3d mean = sum / static_cast<double>(finite_count);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const auto& p : cloud) {
        if (!p.allFinite()) continue;
        const Eigen::Vector3d d = p.cast<double>() - mean;
        scatter.noalias() += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
    Eigen::Vector3d up = solver.eigenvectors().col(0);  // eigenvalues are sorted ascending
    if (up.z() < 0.0) up = -up;
    return up.normalized();
}

}  // namespace lidarloop::core

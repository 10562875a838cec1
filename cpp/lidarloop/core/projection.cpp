#include "lidarloop/core/projection.hpp"

#include <array>

#include <Eigen/Eigenvalues>

#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

constexpr auto kProjectionNames = std::to_array<EnumName<Projection>>({
    {Projection::kHeight, "height"},
    {Projection::kRange, "range"},
});
static_assert(IsOneToOne(kProjectionNames));

constexpr auto kUpVectorModeNames = std::to_array<EnumName<UpVectorMode>>({
    {UpVectorMode::kFixed, "fixed"},
    {UpVectorMode::kPca, "pca"},
});
static_assert(IsOneToOne(kUpVectorModeNames));

}  // namespace

std::string ToString(Projection projection) {
    return std::string(NameOf(kProjectionNames, projection));
}

std::string ToString(UpVectorMode mode) { return std::string(NameOf(kUpVectorModeNames, mode)); }

Projection ParseProjection(std::string_view name) {
    return ParseEnum(kProjectionNames, name, "projection");
}

UpVectorMode ParseUpVectorMode(std::string_view name) {
    return ParseEnum(kUpVectorModeNames, name, "up vector mode");
}

namespace {
// The second eigenvalue's least share of the scatter's trace for the points to span a plane.
constexpr double kMinPlaneSpread = 1e-12;
}  // namespace

Eigen::Vector3d EstimateUpVectorPca(PointsView cloud) {
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
    // Identical or collinear points span no plane: any direction would be as good an "up".
    const Eigen::Vector3d spread = solver.eigenvalues();  // ascending
    if (!(spread(1) > kMinPlaneSpread * spread.sum())) {
        throw EmptyInputError("PCA up vector: the " + std::to_string(finite_count) +
                              " finite points span no plane that PCA can tell (they are "
                              "identical or on one line, or a point far from the rest "
                              "outweighs them); give the up axis instead");
    }
    Eigen::Vector3d up = solver.eigenvectors().col(0);  // eigenvalues are sorted ascending
    if (up.z() < 0.0) up = -up;
    return up.normalized();
}

}  // namespace lidarloop::core

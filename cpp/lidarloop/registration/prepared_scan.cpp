#include "lidarloop/registration/prepared_scan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <Eigen/Eigenvalues>

#include "lidarloop/core/voxel_grid.hpp"

namespace lidarloop::registration {
namespace {

bool Usable(const Eigen::Vector3f& point, const ScanReductionConfig& config) {
    if (!point.allFinite()) return false;
    const double range_m = point.cast<double>().norm();
    return range_m >= config.min_range_m && range_m <= config.max_range_m;
}

// Voxel centroids, in order of first appearance (deterministic for a given scan).
std::vector<Eigen::Vector3f> VoxelCentroids(const core::PointCloud& scan,
                                            const ScanReductionConfig& config,
                                            std::size_t& usable_points) {
    core::VoxelGrid grid(config.voxel_m);
    grid.Reserve(scan.size() / 4);
    for (const auto& point : scan) {
        if (!Usable(point, config)) continue;
        ++usable_points;
        grid.Add(point.cast<double>());
    }
    std::vector<Eigen::Vector3f> centroids;
    centroids.reserve(grid.size());
    for (const core::Voxel& voxel : grid.Voxels())
        centroids.push_back(voxel.centroid.cast<float>());
    return centroids;
}

struct LocalPlane {
    Eigen::Vector3f normal;
    double residual_m = 0.0;  // RMS distance of the neighbours to the plane
};

// The plane through the neighbourhood: its unit normal (the eigenvector of the smallest
// eigenvalue of the covariance) oriented towards the sensor so that both scans agree on its sign.
LocalPlane PlaneAt(const std::vector<Eigen::Vector3f>& points,
                   const std::vector<std::uint32_t>& neighbors, const Eigen::Vector3f& at) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto index : neighbors) mean += points[index].cast<double>();
    mean /= static_cast<double>(neighbors.size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const auto index : neighbors) {
        const Eigen::Vector3d d = points[index].cast<double>() - mean;
        covariance += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(covariance);
    Eigen::Vector3f normal = solver.eigenvectors().col(0).cast<float>();
    if (normal.dot(at) > 0.0F) normal = -normal;
    const double residual_m2 =
        std::max(0.0, solver.eigenvalues()(0)) / static_cast<double>(neighbors.size());
    return {normal, std::sqrt(residual_m2)};
}

// Whether `point` lies on a large plane: the surface variation of its k nearest centroids.
bool OnLargePlane(const std::vector<Eigen::Vector3f>& centroids, const PointTree& tree,
                  const Eigen::Vector3f& point, const ScanReductionConfig& config,
                  std::vector<std::uint32_t>& neighbors) {
    tree.Knn(point, config.distinctive_neighbors, neighbors);
    if (neighbors.size() < 5) return false;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto index : neighbors) mean += centroids[index].cast<double>();
    mean /= static_cast<double>(neighbors.size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const auto index : neighbors) {
        const Eigen::Vector3d d = centroids[index].cast<double>() - mean;
        covariance += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(covariance, Eigen::EigenvaluesOnly);
    const Eigen::Vector3d eigenvalues = solver.eigenvalues().cwiseMax(0.0);
    const double total = eigenvalues.sum();
    return total > 0.0 && eigenvalues(0) / total <= config.max_plane_variation;
}

double Median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
}

// Keeps at most `cap` of the points at an even stride.
void Subsample(std::vector<Eigen::Vector3f>& points, std::vector<Eigen::Vector3f>& normals,
               int cap) {
    const auto limit = static_cast<std::size_t>(cap);
    if (points.size() <= limit) return;
    const double stride = static_cast<double>(points.size()) / static_cast<double>(limit);
    for (std::size_t i = 0; i < limit; ++i) {
        const auto from = static_cast<std::size_t>(static_cast<double>(i) * stride);
        points[i] = points[from];
        normals[i] = normals[from];
    }
    points.resize(limit);
    normals.resize(limit);
}

}  // namespace

SurfacePoints::SurfacePoints(std::vector<Eigen::Vector3f> points,
                             std::vector<Eigen::Vector3f> normals)
    : points_(std::move(points)), normals_(std::move(normals)), tree_((shrink(), &points_)) {}

void SurfacePoints::shrink() {
    points_.shrink_to_fit();
    normals_.shrink_to_fit();
}

std::size_t SurfacePoints::MemoryBytes() const {
    // The tree: an index per point plus about one 64-byte node per 6 points (leaves of <= 12).
    const std::size_t tree_bytes = points_.size() * (sizeof(std::uint32_t) + 64 / 6);
    return (points_.capacity() + normals_.capacity()) * sizeof(Eigen::Vector3f) + tree_bytes;
}

std::size_t PreparedScan::MemoryBytes() const {
    return (structure ? structure->MemoryBytes() : 0) + (ground ? ground->MemoryBytes() : 0) +
           structure_distinctive.capacity();
}

PreparedScan PrepareScan(const core::PointCloud& scan, const ScanReductionConfig& config) {
    PreparedScan prepared;
    prepared.input_points = scan.size();
    const auto centroids = VoxelCentroids(scan, config, prepared.usable_points);
    const PointTree tree(&centroids);
    const float max_vertical_z =
        static_cast<float>(std::cos(config.structure_min_tilt_deg * std::numbers::pi / 180.0));
    std::vector<Eigen::Vector3f> structure, structure_normals, ground, ground_normals;
    std::vector<std::uint32_t> neighbors;
    std::vector<double> structure_residuals_m;
    for (const auto& point : centroids) {
        tree.Knn(point, config.normal_neighbors, neighbors);
        if (neighbors.size() < 5) continue;  // no plane through fewer points
        const LocalPlane plane = PlaneAt(centroids, neighbors, point);
        const bool is_structure = std::abs(plane.normal.z()) <= max_vertical_z;
        (is_structure ? structure : ground).push_back(point);
        (is_structure ? structure_normals : ground_normals).push_back(plane.normal);
        if (is_structure) structure_residuals_m.push_back(plane.residual_m);
    }
    prepared.structure_roughness_m = Median(std::move(structure_residuals_m));
    Subsample(structure, structure_normals, config.max_structure_points);
    Subsample(ground, ground_normals, config.max_ground_points);
    prepared.structure_distinctive.reserve(structure.size());
    for (const auto& point : structure) {
        prepared.structure_distinctive.push_back(
            OnLargePlane(centroids, tree, point, config, neighbors) ? 0 : 1);
    }
    prepared.structure =
        std::make_shared<const SurfacePoints>(std::move(structure), std::move(structure_normals));
    prepared.ground =
        std::make_shared<const SurfacePoints>(std::move(ground), std::move(ground_normals));
    return prepared;
}

}  // namespace lidarloop::registration

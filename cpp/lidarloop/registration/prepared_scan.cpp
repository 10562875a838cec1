#include "lidarloop/registration/prepared_scan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include <Eigen/Cholesky>

#include "lidarloop/core/eigen3x3.hpp"
#include "lidarloop/core/voxel_grid.hpp"
#include "lidarloop/registration/neighbor_grid.hpp"

namespace lidarloop::registration {
namespace {

bool Usable(const Eigen::Vector3f& point, const ScanReductionConfig& config) {
    if (!point.allFinite()) return false;
    const double range_m = point.cast<double>().norm();
    return range_m >= config.min_range_m && range_m <= config.max_range_m;
}

// A sum of `count` points over their count; NaN for none.
Eigen::Vector3d MeanOf(const Eigen::Vector3d& sum, std::size_t count) {
    if (count == 0) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    return sum / static_cast<double>(count);
}

// The voxel centroids of the usable points, in order of first appearance (deterministic for a
// given scan); counts the points and, in the same pass, finds their mean (the view centre).
std::vector<Eigen::Vector3f> VoxelCentroids(const core::PointCloud& scan,
                                            const ScanReductionConfig& config,
                                            std::size_t& usable_points,
                                            Eigen::Vector3d& view_centre) {
    core::VoxelGrid grid(config.voxel_m);
    grid.Reserve(scan.size() / 4);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto& point : scan) {
        if (!Usable(point, config)) continue;
        ++usable_points;
        const Eigen::Vector3d p = point.cast<double>();
        sum += p;
        grid.Add(p);
    }
    view_centre = MeanOf(sum, usable_points);
    std::vector<Eigen::Vector3f> centroids;
    centroids.reserve(grid.size());
    for (const core::Voxel& voxel : grid.Voxels())
        centroids.push_back(voxel.centroid.cast<float>());
    return centroids;
}

// The neighbourhood's scatter: the sum of the outer products of the points less their mean.
// Six scalar sums in the neighbours' order: the values of Eigen's `c += d * d.transpose()`
// (each entry is the same products added in the same order), without its shuffles and spills.
Eigen::Matrix3d ScatterOf(const std::vector<Eigen::Vector3f>& points,
                          const std::vector<std::uint32_t>& neighbors) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto index : neighbors) mean += points[index].cast<double>();
    mean /= static_cast<double>(neighbors.size());
    double xx = 0.0, xy = 0.0, xz = 0.0, yy = 0.0, yz = 0.0, zz = 0.0;
    for (const auto index : neighbors) {
        const Eigen::Vector3d d = points[index].cast<double>() - mean;
        xx += d.x() * d.x();
        xy += d.x() * d.y();
        xz += d.x() * d.z();
        yy += d.y() * d.y();
        yz += d.y() * d.z();
        zz += d.z() * d.z();
    }
    Eigen::Matrix3d scatter;
    scatter << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return scatter;
}

// The plane through the neighbourhood: its unit normal (the eigenvector of the smallest
// eigenvalue of the covariance) oriented towards the sensor so that both scans agree on its sign.
// The closed-form eigenvalues and one cross product: Eigen's computeDirect also derives the two
// eigenvectors not needed here and calls libm (a tenth of PrepareScan; tested against it).
Eigen::Vector3f NormalAt(const std::vector<Eigen::Vector3f>& points,
                         const std::vector<std::uint32_t>& neighbors, const Eigen::Vector3f& at) {
    const Eigen::Matrix3d scatter = ScatterOf(points, neighbors);
    const double smallest = core::SymmetricEigenvaluesDescending(scatter).z();
    Eigen::Vector3f normal = core::SymmetricEigenvector(scatter, smallest).cast<float>();
    if (normal.dot(at) > 0.0F) normal = -normal;
    return normal;
}

// Whether `point` lies on a large plane: the surface variation lambda0 / (lambda0 + lambda1 +
// lambda2) of its k nearest centroids is at most max_plane_variation. A yes or no needs no
// eigenvalues (their trigonometry): lambda0 exceeds t exactly when the scatter less t times the
// identity is positive definite, which its Cholesky factorisation tells; t is the bound times
// the trace, the eigenvalues' sum.
bool OnLargePlane(const std::vector<Eigen::Vector3f>& centroids, const NeighborGrid& grid,
                  const Eigen::Vector3f& point, const ScanReductionConfig& config,
                  NeighborGrid::Scratch& scratch, std::vector<std::uint32_t>& neighbors) {
    grid.Knn(point, config.distinctive_neighbors, scratch, neighbors);
    if (neighbors.size() < 5) return false;
    const Eigen::Matrix3d scatter = ScatterOf(centroids, neighbors);
    const double total = scatter.trace();
    if (!(total > 0.0)) return false;
    const Eigen::LLT<Eigen::Matrix3d> cholesky(scatter - config.max_plane_variation * total *
                                                             Eigen::Matrix3d::Identity());
    return cholesky.info() != Eigen::Success;
}

// The overlap test's gates at their defaults, with which a scan is matched to itself.
struct SelfMatchGates {
    float range_m = static_cast<float>(AcceptanceConfig{}.overlap_range_m);
    float partner_m = static_cast<float>(AcceptanceConfig{}.overlap_radius_m);
    float plane_m = static_cast<float>(AcceptanceConfig{}.overlap_plane_m);
};

// Partners per probed point: the nearest lies along the scan line, closer than a second scan's
// samples fall; four reach across the lines as well (docs/verification.md).
constexpr int kSelfPartners = 4;
// Probed points at most (an even stride): the statistic is an RMS over thousands of pairs.
constexpr std::size_t kSelfProbes = 1000;

// PreparedScan::structure_roughness_m: structure points against the planes of their nearest
// other structure points, as the overlap test pairs two scans. Sampling, noise and surface
// kind set how far apart and how flat such partners are, in one scan as between two.
double SelfResidual(const SurfacePoints& structure) {
    const SelfMatchGates gates;
    const std::size_t stride = std::max<std::size_t>(1, structure.size() / kSelfProbes);
    std::vector<std::uint32_t> nearest;
    NeighborGrid::Scratch scratch;
    double squared_sum_m2 = 0.0;
    std::size_t pairs = 0;
    for (std::size_t i = 0; i < structure.size(); i += stride) {
        const Eigen::Vector3f& point = structure.points()[i];
        if (point.norm() > gates.range_m) continue;
        structure.grid().Knn(point, kSelfPartners + 1, scratch, nearest);
        for (const std::uint32_t partner : nearest) {
            if (partner == i) continue;
            const Eigen::Vector3f& partner_normal = structure.normals()[partner];
            const Eigen::Vector3f offset = point - structure.points()[partner];
            const float distance_m = partner_normal.dot(offset);
            if (offset.norm() > gates.partner_m || std::abs(distance_m) > gates.plane_m ||
                std::abs(partner_normal.dot(structure.normals()[i])) < kOverlapMinNormalCosine) {
                continue;
            }
            squared_sum_m2 += static_cast<double>(distance_m) * distance_m;
            ++pairs;
        }
    }
    return pairs == 0 ? 0.0 : std::sqrt(squared_sum_m2 / static_cast<double>(pairs));
}

// Columns of a surface's search grid, metres: ICP's partners and the overlap test's lie within
// 0.6-3 m, and a registered partner's hint within centimetres, so a query reads a few columns.
constexpr float kSearchColumnM = 1.0F;

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
    : points_(std::move(points)),
      normals_(std::move(normals)),
      grid_((shrink(), points_), kSearchColumnM) {}

void SurfacePoints::shrink() {
    points_.shrink_to_fit();
    normals_.shrink_to_fit();
}

std::size_t SurfacePoints::MemoryBytes() const {
    return (points_.capacity() + normals_.capacity()) * sizeof(Eigen::Vector3f) +
           grid_.MemoryBytes();
}

std::size_t PreparedScan::MemoryBytes() const {
    return (structure ? structure->MemoryBytes() : 0) + (ground ? ground->MemoryBytes() : 0) +
           structure_distinctive.capacity();
}

PreparedScan PrepareScan(const core::PointCloud& scan, const ScanReductionConfig& config) {
    PreparedScan prepared;
    prepared.input_points = scan.size();
    const auto centroids =
        VoxelCentroids(scan, config, prepared.usable_points, prepared.view_centre);
    const NeighborGrid grid(centroids, static_cast<float>(config.voxel_m));
    NeighborGrid::Scratch scratch;
    const float max_vertical_z =
        static_cast<float>(std::cos(config.structure_min_tilt_deg * std::numbers::pi / 180.0));
    std::vector<std::uint32_t> neighbors;
    // Zero: no plane through fewer than 5 points.
    std::vector<Eigen::Vector3f> normals(centroids.size(), Eigen::Vector3f::Zero());
    for (const std::uint32_t i : grid.SpatialOrder()) {
        grid.Knn(centroids[i], config.normal_neighbors, scratch, neighbors);
        if (neighbors.size() >= 5) normals[i] = NormalAt(centroids, neighbors, centroids[i]);
    }
    std::vector<Eigen::Vector3f> structure, structure_normals, ground, ground_normals;
    for (std::size_t i = 0; i < centroids.size(); ++i) {
        if (normals[i].isZero()) continue;
        const bool is_structure = std::abs(normals[i].z()) <= max_vertical_z;
        (is_structure ? structure : ground).push_back(centroids[i]);
        (is_structure ? structure_normals : ground_normals).push_back(normals[i]);
    }
    Subsample(structure, structure_normals, config.max_structure_points);
    Subsample(ground, ground_normals, config.max_ground_points);
    prepared.structure_distinctive.assign(structure.size(), 0);
    NeighborGrid::Scratch wide_scratch;
    // Asked in a spatial order too: a grid of the structure points gives one.
    const NeighborGrid structure_order(structure, static_cast<float>(config.voxel_m));
    for (const std::uint32_t i : structure_order.SpatialOrder()) {
        prepared.structure_distinctive[i] =
            OnLargePlane(centroids, grid, structure[i], config, wide_scratch, neighbors) ? 0 : 1;
    }
    prepared.structure =
        std::make_shared<const SurfacePoints>(std::move(structure), std::move(structure_normals));
    prepared.ground =
        std::make_shared<const SurfacePoints>(std::move(ground), std::move(ground_normals));
    prepared.structure_roughness_m = SelfResidual(*prepared.structure);
    return prepared;
}

Eigen::Vector3d ViewCentre(const core::PointCloud& scan, const ScanReductionConfig& config) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t usable = 0;
    for (const auto& point : scan) {
        if (!Usable(point, config)) continue;
        sum += point.cast<double>();
        ++usable;
    }
    return MeanOf(sum, usable);
}

}  // namespace lidarloop::registration

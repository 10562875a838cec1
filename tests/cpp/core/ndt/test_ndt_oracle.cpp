// Oracle tests: the fast NDT descriptor (sorted voxel moments, closed-form eigenvalues, batched
// classification, float nearest-line search over rotated centres) against a plain reference
// built from the definitions: brute-force cells, Eigen's iterative eigen solver, eq. (2) in
// double precision on rotated axes.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "lidarloop/core/ndt/ndt_descriptor.hpp"
#include "lidarloop/core/ndt/sphere_partition.hpp"
#include "ndt_reference.hpp"

namespace lidarloop::core {
namespace {

using test_reference::StreetScan;

// Ratios or dot products this close to a class border may land on either side of it in the
// fast path (eigenvalues to 1e-8 l1, axes and dot products in float, ~1e-7); such cells may count
// in another column. Measured: none moved on these scans.
constexpr double kRatioMargin = 1e-6;
constexpr double kLineMargin = 1e-5;

// Eq. (2) in double: the nearest line, and whether the runner-up is within kLineMargin.
struct NearestLineResult {
    int index = 0;
    bool borderline = false;
};
NearestLineResult NearestLineWithMargin(const HalfSpherePartition& partition,
                                        const Eigen::Vector3d& axis) {
    std::vector<double> dots;
    for (const auto& centre : partition.centres()) dots.push_back(std::abs(axis.dot(centre)));
    const auto best = std::max_element(dots.begin(), dots.end());
    NearestLineResult result{static_cast<int>(best - dots.begin()), false};
    for (std::size_t j = 0; j < dots.size(); ++j) {
        if (static_cast<int>(j) != result.index && *best - dots[j] < kLineMargin) {
            result.borderline = true;
        }
    }
    return result;
}

bool NearBorder(double ratio, double border) { return std::abs(ratio - border) < kRatioMargin; }

// The unnormalised descriptor F of eq. (3) seen after rotating the scan by R, from the
// definitions, and the number of cells near a class border.
struct ReferenceDescriptor {
    std::vector<double> counts;
    int borderline_cells = 0;
    int classified_cells = 0;
};

class ReferenceBuilder {
public:
    ReferenceBuilder(const PointCloud& cloud, const NdtConfig& config)
        : config_(config),
          cells_(test_reference::BruteForceCells(cloud, config.cell_size_m,
                                                 config.min_points_per_cell)) {
        if (config.planar_classes > 0) planar_.emplace(config.planar_classes);
        if (config.linear_classes > 0) linear_.emplace(config.linear_classes);
    }

    ReferenceDescriptor Build(const Eigen::Matrix3d& R) const {
        ReferenceDescriptor out;
        out.counts.assign(static_cast<std::size_t>(config_.RangeCount() * config_.FeatureCount()),
                          0.0);
        for (const NdtCell& cell : cells_) AddCell(cell, R, out);
        return out;
    }

private:
    void AddCell(const NdtCell& cell, const Eigen::Matrix3d& R, ReferenceDescriptor& out) const {
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cell.covariance_m2);
        const Eigen::Vector3d values = solver.eigenvalues().cwiseMax(0.0);  // ascending
        const double l1 = values(2), l2 = values(1), l3 = values(0);
        if (l1 <= 1e-12 * std::max(cell.covariance_m2.trace(), 1.0)) return;  // degenerate
        const double t_e = config_.eigen_ratio_threshold;
        const double linear_ratio = l2 / l1;
        const double planar_ratio = l2 > 0.0 ? l3 / l2 : 0.0;
        bool borderline = NearBorder(linear_ratio, t_e) || NearBorder(planar_ratio, t_e);
        int column = -1;
        if (linear_ratio < t_e) {
            column = OrientedColumn(linear_, R * solver.eigenvectors().col(2),
                                    config_.spherical_classes + config_.planar_classes, borderline);
        } else if (planar_ratio < t_e) {
            column = OrientedColumn(planar_, R * solver.eigenvectors().col(0),
                                    config_.spherical_classes, borderline);
        } else if (config_.spherical_classes > 0) {
            const int s = config_.spherical_classes;
            const double t = (linear_ratio - t_e) / (1.0 - t_e) * s;
            for (int k = 1; k < s; ++k) borderline |= NearBorder(t, k);
            column = std::clamp(static_cast<int>(t), 0, s - 1);
        }
        out.borderline_cells += borderline ? 1 : 0;
        if (column < 0) return;  // its shape has no classes
        ++out.classified_cells;
        int row = 0;
        for (double limit : config_.range_limits_m) row += cell.mean_m.norm() >= limit ? 1 : 0;
        out.counts[static_cast<std::size_t>(row * config_.FeatureCount() + column)] += 1.0;
    }

    static int OrientedColumn(const std::optional<HalfSpherePartition>& partition,
                              const Eigen::Vector3d& axis, int first_column, bool& borderline) {
        if (!partition) return -1;
        const NearestLineResult nearest = NearestLineWithMargin(*partition, axis);
        borderline |= nearest.borderline;
        return first_column + nearest.index;
    }

    NdtConfig config_;
    std::vector<NdtCell> cells_;
    std::optional<HalfSpherePartition> planar_;
    std::optional<HalfSpherePartition> linear_;
};

// Every descriptor of the fast set against the reference under the same rotation: a cell may
// move only if it is near a class border, and then it changes two counts by one each.
void ExpectSetMatchesReference(const PointCloud& cloud, const NdtConfig& config) {
    const NdtDescriptorSet set = ComputeNdtDescriptorSet(cloud, config);
    const ReferenceBuilder reference(cloud, config);
    ASSERT_FALSE(set.descriptors.empty());
    for (const NdtDescriptor& f : set.descriptors) {
        const ReferenceDescriptor expected = reference.Build(f.R_aligned_sensor);
        ASSERT_EQ(f.counts.size(), expected.counts.size());
        double moved = 0.0;
        for (std::size_t i = 0; i < f.counts.size(); ++i) {
            moved += std::abs(f.counts[i] - expected.counts[i]);
        }
        EXPECT_LE(moved, 2.0 * expected.borderline_cells) << "rotation\n" << f.R_aligned_sensor;
        EXPECT_NEAR(f.total, expected.classified_cells, expected.borderline_cells);
        // A reference with many border cases would let real errors through.
        EXPECT_LT(expected.borderline_cells, expected.classified_cells / 100 + 2);
        EXPECT_GT(expected.classified_cells, 1000);
    }
}

TEST(NdtOracle, PaperDefaultsWithRotationCandidatesMatchTheDefinitions) {
    const NdtConfig config;  // s = 1, p = 9, l = 1, rotation normalised
    ExpectSetMatchesReference(StreetScan(1).Build(), config);
}

// A street scan and its mirror through the sensor: the centroid of the cells is too short to
// choose the sign of a line, so both are kept, and candidates come in pairs that differ by a
// half turn about z, the second of which is derived from the first by moving columns (the paper's
// p = 9 partition maps onto itself under that turn). Each must match the definitions as well.
TEST(NdtOracle, HalfTurnedCandidatesMatchTheDefinitions) {
    PointCloud scan = StreetScan(5).Build();
    const std::size_t n = scan.size();
    for (std::size_t i = 0; i < n; ++i) scan.push_back(-scan[i]);
    const NdtConfig config;
    const NdtDescriptorSet set = ComputeNdtDescriptorSet(scan, config);
    const Eigen::Matrix3d half_turn = Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal();
    int pairs = 0;
    for (const NdtDescriptor& a : set.descriptors) {
        for (const NdtDescriptor& b : set.descriptors) {
            pairs += (half_turn * a.R_aligned_sensor).isApprox(b.R_aligned_sensor, 1e-9);
        }
    }
    EXPECT_GE(pairs, 2) << "no half-turn pair: the test would prove nothing";
    ExpectSetMatchesReference(scan, config);
}

TEST(NdtOracle, SubClassesOfEveryShapeMatchTheDefinitions) {
    NdtConfig config;
    config.spherical_classes = 3;
    config.planar_classes = 9;
    config.linear_classes = 4;
    config.range_limits_m = {2.0, 5.0, 10.0};
    for (const bool normalise : {false, true}) {
        SCOPED_TRACE(normalise);
        config.normalise_rotation = normalise;
        ExpectSetMatchesReference(StreetScan(2).Build(), config);
    }
}

TEST(NdtOracle, CoarseCellsAndALooserThresholdMatchTheDefinitions) {
    NdtConfig config;
    config.cell_size_m = 1.0;
    config.min_points_per_cell = 8;
    config.eigen_ratio_threshold = 0.25;
    config.planar_classes = 16;
    ExpectSetMatchesReference(StreetScan(3).Build(), config);
}

TEST(NdtOracle, CellStatisticsCountTheSparseCells) {
    const PointCloud scan = StreetScan(4).Build();
    const NdtConfig config;
    const NdtDescriptorSet set = ComputeNdtDescriptorSet(scan, config);
    std::size_t sparse = 0;
    for (const auto& [index, points] :
         test_reference::BruteForceCellPoints(scan, config.cell_size_m)) {
        sparse += static_cast<int>(points.size()) < config.min_points_per_cell ? 1 : 0;
    }
    EXPECT_EQ(set.cell_stats.sparse_cells, sparse);
    EXPECT_EQ(set.cell_stats.points_used, scan.size());
    EXPECT_EQ(set.cell_stats.points_skipped, 0U);
}

}  // namespace
}  // namespace lidarloop::core

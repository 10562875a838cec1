#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "lidarloop/core/eigen3x3.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/ndt/ndt_cells.hpp"
#include "lidarloop/core/ndt/ndt_descriptor.hpp"
#include "lidarloop/core/ndt/ndt_shape.hpp"
#include "lidarloop/core/ndt/sphere_partition.hpp"
#include "ndt_reference.hpp"
#include "test_utils.hpp"

namespace lidarloop::core {
namespace {

using test::RandomRotation;
using test::Transformed;

void ExpectCellsMatchBruteForce(const PointCloud& cloud, double q, int min_points) {
    std::vector<NdtCell> expected = test_reference::BruteForceCells(cloud, q, min_points);
    const auto cells = ComputeNdtCells(cloud, q, min_points);
    ASSERT_EQ(cells.size(), expected.size());
    // Both lists are sorted by (z, y, x) cell index: the map's order is (x, y, z), so match
    // by mean instead of position.
    auto by_mean = [](const NdtCell& a, const NdtCell& b) {
        return std::lexicographical_compare(a.mean_m.data(), a.mean_m.data() + 3, b.mean_m.data(),
                                            b.mean_m.data() + 3);
    };
    auto sorted_cells = cells;
    std::sort(sorted_cells.begin(), sorted_cells.end(), by_mean);
    std::sort(expected.begin(), expected.end(), by_mean);
    // Cells whose means agree to the last bits in x can sort either way round in the two lists:
    // each expected cell takes the first unmatched cell of equal mean a few places around it.
    constexpr std::size_t kWindow = 8;
    std::vector<bool> matched(sorted_cells.size(), false);
    for (std::size_t i = 0; i < expected.size(); ++i) {
        const std::size_t first = i < kWindow ? 0 : i - kWindow;
        const std::size_t last = std::min(sorted_cells.size(), i + kWindow + 1);
        std::size_t k = first;
        while (k < last &&
               (matched[k] || (sorted_cells[k].mean_m - expected[i].mean_m).norm() >= 1e-9))
            ++k;
        ASSERT_LT(k, last) << "no cell with the mean " << expected[i].mean_m.transpose();
        matched[k] = true;
        EXPECT_EQ(sorted_cells[k].point_count, expected[i].point_count);
        EXPECT_LT((sorted_cells[k].covariance_m2 - expected[i].covariance_m2).norm(), 1e-9);
    }
}

TEST(NdtCells, MatchBruteForceStatisticsOnRandomClouds) {
    for (unsigned seed : {1U, 2U, 3U}) {
        SCOPED_TRACE(seed);
        ExpectCellsMatchBruteForce(test::RandomCloud(4000, seed, 2.0f), 0.8, 4);
    }
}

// Small clumps spread over 160 m with 5 cm voxels: cell keys need about 40 bits, so the voxel
// sort runs more digit passes than a compact scan needs.
TEST(NdtCells, MatchBruteForceOnAWideSparseCloud) {
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> centre(-80.0f, 80.0f);
    std::normal_distribution<float> spread(0.0f, 0.03f);
    PointCloud cloud;
    for (int clump = 0; clump < 150; ++clump) {
        // One draw per statement: the order of a call's arguments is the compiler's choice.
        const float z = centre(rng) / 8.0f;
        const float y = centre(rng);
        const Eigen::Vector3f c(centre(rng), y, z);
        for (int i = 0; i < 25; ++i) {
            const float dz = spread(rng);
            const float dy = spread(rng);
            cloud.push_back(c + Eigen::Vector3f(spread(rng), dy, dz));
        }
    }
    ExpectCellsMatchBruteForce(cloud, 0.1, 3);
}

TEST(NdtCells, EveryPointIsInEightCells) {
    const PointCloud cloud = test::RandomCloud(3000, 4, 3.0f);
    NdtCellStats stats;
    const auto cells = ComputeNdtCells(cloud, 0.5, 2, &stats);
    std::size_t total = 0;
    for (const auto& cell : cells) total += static_cast<std::size_t>(cell.point_count);
    // With a minimum of 2, every dropped (sparse) cell held exactly one point.
    EXPECT_EQ(total + stats.sparse_cells, 8 * cloud.size());
    EXPECT_EQ(stats.points_used, cloud.size());
    const PointCloud pair = {{0.1f, 0.1f, 0.1f}, {0.12f, 0.1f, 0.1f}};
    EXPECT_EQ(ComputeNdtCells(pair, 0.5, 2).size(), 8U);  // both points share all 8 cells
}

TEST(NdtCells, SkipsNonFiniteAndRejectsBadParameters) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    NdtCellStats stats;
    const auto cells =
        ComputeNdtCells({{nan, 0, 0}, {1e9f, 0, 0}, {0, 0, 0}, {0, 0, 0.1f}}, 0.5, 2, &stats);
    EXPECT_EQ(stats.points_skipped, 2U);
    EXPECT_EQ(stats.points_used, 2U);
    EXPECT_THROW(ComputeNdtCells({}, 0.0, 5), ConfigError);
    EXPECT_THROW(ComputeNdtCells({}, NAN, 5), ConfigError);
    EXPECT_THROW(ComputeNdtCells({}, 0.5, 1), ConfigError);
    EXPECT_TRUE(ComputeNdtCells({}, 0.5, 5).empty());
}

PointCloud PlanePoints(const Eigen::Vector3d& normal, int count, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    const Eigen::Vector3d a = normal.unitOrthogonal();
    const Eigen::Vector3d b = normal.cross(a);
    PointCloud cloud;
    for (int i = 0; i < count; ++i) {
        const double along_a = u(rng);
        cloud.push_back((Eigen::Vector3d(4, 2, 1) + along_a * a + u(rng) * b).cast<float>());
    }
    return cloud;
}

TEST(NdtClassify, PlaneIsPlanarWithItsNormal) {
    const Eigen::Vector3d normal = Eigen::Vector3d(1, 2, 3).normalized();
    const auto cells = ComputeNdtCells(PlanePoints(normal, 20000, 5), 0.5, 5);
    ASSERT_FALSE(cells.empty());
    for (const auto& cell : cells) {
        // A cell at the rim of the 6 m square patch may hold a thin sliver, a line; skip those.
        const Eigen::Vector3d offset = cell.mean_m - Eigen::Vector3d(4, 2, 1);
        if (offset.cwiseAbs().maxCoeff() > 2.0 || cell.point_count < 50) continue;
        const auto info = ClassifyCovariance(cell.covariance_m2, 0.1);
        ASSERT_EQ(info.shape, CellShape::kPlanar);
        EXPECT_GT(std::abs(info.axis.dot(normal)), 0.999);
    }
}

TEST(NdtClassify, LineIsLinearAlongItsAxis) {
    const Eigen::Vector3d axis = Eigen::Vector3d(-1, 0.5, 0.2).normalized();
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> u(-5.0, 5.0);
    PointCloud cloud;
    for (int i = 0; i < 5000; ++i) cloud.push_back((u(rng) * axis).cast<float>());
    const auto cells = ComputeNdtCells(cloud, 0.5, 5);
    ASSERT_FALSE(cells.empty());
    for (const auto& cell : cells) {
        const auto info = ClassifyCovariance(cell.covariance_m2, 0.1);
        ASSERT_EQ(info.shape, CellShape::kLinear);
        EXPECT_GT(std::abs(info.axis.dot(axis)), 0.999);
    }
}

TEST(NdtClassify, IsotropicBlobIsSpherical) {
    const auto info = ClassifyCovariance(Eigen::Vector3d(1.0, 0.9, 0.8).asDiagonal(), 0.1);
    EXPECT_EQ(info.shape, CellShape::kSpherical);
    const PointCloud blob = test::RandomCloud(20000, 7, 0.2f);  // a cube fills its cells evenly
    const auto cells = ComputeNdtCells(blob, 0.5, 50);
    std::size_t spherical = 0;
    for (const auto& cell : cells) {
        spherical += ClassifyCovariance(cell.covariance_m2, 0.1).shape == CellShape::kSpherical;
    }
    EXPECT_EQ(spherical, cells.size());
}

TEST(NdtClassify, ThresholdBordersAndDegenerateInput) {
    // Just above and below t_e on each ratio (the paper's tests are strict '<').
    EXPECT_EQ(ClassifyCovariance(Eigen::Vector3d(1.0, 0.1001, 0.05).asDiagonal(), 0.1).shape,
              CellShape::kSpherical);
    EXPECT_EQ(ClassifyCovariance(Eigen::Vector3d(1.0, 0.099, 0.05).asDiagonal(), 0.1).shape,
              CellShape::kLinear);
    EXPECT_EQ(ClassifyCovariance(Eigen::Vector3d(1.0, 0.5, 0.049).asDiagonal(), 0.1).shape,
              CellShape::kPlanar);
    EXPECT_EQ(ClassifyCovariance(Eigen::Matrix3d::Zero(), 0.1).shape, CellShape::kDegenerate);
    Eigen::Matrix3d nan = Eigen::Matrix3d::Identity();
    nan(0, 1) = NAN;
    EXPECT_EQ(ClassifyCovariance(nan, 0.1).shape, CellShape::kDegenerate);
}

TEST(NdtClassify, BatchOverColumnsEqualsOneByOne) {
    // Planes, lines, blobs over many scales and orientations, plus degenerate and non-finite
    // covariances: the vectorised batch must agree exactly with ClassifyCovariance.
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> log_scale(-6.0, 1.0);
    NdtCellColumns columns;
    std::vector<Eigen::Matrix3d> covariances;
    for (int i = 0; i < 3000; ++i) {
        const Eigen::Matrix3d R = RandomRotation(rng);
        const Eigen::Vector3d lambda{std::pow(10.0, log_scale(rng)), std::pow(10.0, log_scale(rng)),
                                     std::pow(10.0, log_scale(rng))};
        covariances.push_back(R * lambda.asDiagonal() * R.transpose());
    }
    covariances.push_back(Eigen::Matrix3d::Zero());
    covariances.push_back(Eigen::Vector3d(2.0, 2.0, 0.0).asDiagonal());  // repeated eigenvalue
    covariances.push_back(Eigen::Vector3d(1.0, 0.0, 0.0).asDiagonal());
    Eigen::Matrix3d infinite = Eigen::Matrix3d::Identity();
    infinite(1, 2) = infinite(2, 1) = std::numeric_limits<double>::infinity();
    covariances.push_back(infinite);
    for (const Eigen::Matrix3d& c : covariances) {
        columns.point_count.push_back(10);
        for (auto* mean : {&columns.mean_x_m, &columns.mean_y_m, &columns.mean_z_m}) {
            mean->push_back(1.0);
        }
        columns.cov_xx_m2.push_back(c(0, 0));
        columns.cov_xy_m2.push_back(c(0, 1));
        columns.cov_xz_m2.push_back(c(0, 2));
        columns.cov_yy_m2.push_back(c(1, 1));
        columns.cov_yz_m2.push_back(c(1, 2));
        columns.cov_zz_m2.push_back(c(2, 2));
    }
    CellShapeColumns shapes;
    ClassifyCells(columns, 0.1, shapes);
    ASSERT_EQ(shapes.size(), covariances.size());
    std::map<CellShape, int> seen;
    for (std::size_t i = 0; i < covariances.size(); ++i) {
        const CellShapeInfo expected = ClassifyCovariance(covariances[i], 0.1);
        ASSERT_EQ(shapes.shape[i], expected.shape) << covariances[i];
        EXPECT_EQ(shapes.l2_over_l1[i], expected.l2_over_l1);
        EXPECT_EQ(Eigen::Vector3d(shapes.axis_x[i], shapes.axis_y[i], shapes.axis_z[i]),
                  expected.axis);
        ++seen[expected.shape];
    }
    for (CellShape shape :
         {CellShape::kSpherical, CellShape::kPlanar, CellShape::kLinear, CellShape::kDegenerate}) {
        EXPECT_GT(seen[shape], 0) << "the input lacks a shape: the test would prove less";
    }
    // The plane (2, 2, 0), whose in-plane eigenvalues are equal, still gets its normal from the
    // cross products (the normal's own eigenvalue is apart from both, so two rows of A - l3 I
    // stay independent; the solver fallback is only a guard against rounding).
    EXPECT_NEAR(std::abs(shapes.axis_z[covariances.size() - 3]), 1.0, 1e-12);
}

TEST(NdtCells, ColumnsHoldTheSameCellsAsTheList) {
    const PointCloud cloud = test::RandomCloud(5000, 17, 3.0f);
    NdtCellStats list_stats;
    NdtCellStats column_stats;
    const auto cells = ComputeNdtCells(cloud, 0.5, 3, &list_stats);
    NdtCellColumns columns;
    columns.point_count.push_back(99);  // stale content must be cleared
    ComputeNdtCellColumns(cloud, 0.5, 3, columns, &column_stats);
    ASSERT_EQ(columns.size(), cells.size());
    ASSERT_GT(cells.size(), 100U);
    for (std::size_t i = 0; i < cells.size(); ++i) {
        const NdtCell cell = columns.Cell(i);
        EXPECT_EQ(cell.point_count, cells[i].point_count);
        EXPECT_EQ(cell.mean_m, cells[i].mean_m);
        EXPECT_EQ(cell.covariance_m2, cells[i].covariance_m2);
    }
    EXPECT_EQ(column_stats.sparse_cells, list_stats.sparse_cells);
    EXPECT_EQ(column_stats.points_used, list_stats.points_used);
}

// A synthetic scan with floor, walls at uneven angles, poles and clutter.
PointCloud StructuredScan(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::normal_distribution<float> noise(0.0f, 0.01f);
    PointCloud cloud;
    for (int i = 0; i < 30000; ++i) {
        cloud.push_back({-20 + 40 * u(rng), -20 + 40 * u(rng), -1.7f + noise(rng)});
    }
    for (int i = 0; i < 15000; ++i) {  // a long wall at x = 6
        cloud.push_back({6.0f + noise(rng), -15 + 30 * u(rng), -1.7f + 4 * u(rng)});
    }
    for (int i = 0; i < 8000; ++i) {  // a shorter wall at 60 degrees
        const float t = 12 * u(rng);
        cloud.push_back({-3 - 0.5f * t + noise(rng), 4 + 0.866f * t, -1.7f + 3 * u(rng)});
    }
    for (int i = 0; i < 3000; ++i) {  // a pole
        cloud.push_back({2.0f + noise(rng), -4.0f + noise(rng), -1.7f + 5 * u(rng)});
    }
    return cloud;
}

// The floor any revisit sees: the same scan moved by a fraction of a cell falls differently
// into the grid. A rotated scan cannot do better than that.
double TranslationFloor(const PointCloud& cloud, const NdtDescriptorSet& reference,
                        const NdtConfig& config) {
    const PointCloud moved =
        Transformed(cloud, Eigen::Matrix3f::Identity(), Eigen::Vector3f(0.11f, 0.07f, 0.13f));
    return NdtSetDifference(reference, ComputeNdtDescriptorSet(moved, config));
}

TEST(NdtDescriptor, RotatedScanHasSmallSigmaWhileUnnormalisedDiffers) {
    const PointCloud cloud = StructuredScan(8);
    std::mt19937 rng(9);
    NdtConfig config;
    NdtConfig unnormalised = config;
    unnormalised.normalise_rotation = false;
    const auto reference = ComputeNdtDescriptorSet(cloud, config);
    const auto reference_raw = ComputeNdtDescriptorSet(cloud, unnormalised);
    const double grid_floor = TranslationFloor(cloud, reference, config);
    EXPECT_GT(grid_floor, 0.0);
    // Every rotated copy stays near the floor. The unnormalised descriptor proves the rotations
    // mattered: it differs by ~1 for tilts, less (0.15-0.3) for turns mostly about the floor's
    // normal, which keep the floor cells in their class; so it is compared in sum.
    double sigma_sum = 0.0;
    double raw_sum = 0.0;
    for (int trial = 0; trial < 8; ++trial) {
        const Eigen::Matrix3f R = RandomRotation(rng).cast<float>();
        const PointCloud rotated = Transformed(cloud, R);
        const double sigma = NdtSetDifference(reference, ComputeNdtDescriptorSet(rotated, config));
        const double raw =
            NdtSetDifference(reference_raw, ComputeNdtDescriptorSet(rotated, unnormalised));
        EXPECT_LT(sigma, std::max(0.08, 3.0 * grid_floor)) << "trial " << trial;
        sigma_sum += sigma;
        raw_sum += raw;
    }
    EXPECT_GT(raw_sum, 8.0 * sigma_sum);
    // A quarter turn about z maps the grid onto itself: then the result is exact.
    Eigen::Matrix3f quarter;
    quarter << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // exact in float, unlike AngleAxisf(pi/2)
    EXPECT_EQ(
        NdtSetDifference(reference, ComputeNdtDescriptorSet(Transformed(cloud, quarter), config)),
        0.0);
}

// Street scans hold several surfaces whose normals share a class of the sensor-fixed partition
// in one orientation and not in another (walls 48 degrees apart, ground and a roof 21 degrees
// apart). Peaks taken from those classes turned differently from the scan (sigma' 0.15-0.25 on
// average for rotated copies, up to 0.5, as bad as no normalisation); modes of the normals turn
// with it, so every rotated copy stays near the translation floor.
TEST(NdtDescriptor, RotatedStreetScansStayAtTheTranslationFloor) {
    const NdtConfig config;
    NdtConfig unnormalised = config;
    unnormalised.normalise_rotation = false;
    for (unsigned seed = 1; seed <= 3; ++seed) {
        SCOPED_TRACE(seed);
        const PointCloud cloud = test_reference::StreetScan(seed).Build();
        const auto reference = ComputeNdtDescriptorSet(cloud, config);
        const auto reference_raw = ComputeNdtDescriptorSet(cloud, unnormalised);
        const double grid_floor = TranslationFloor(cloud, reference, config);
        std::mt19937 rng(seed + 20);
        double raw_sum = 0.0;
        double sigma_sum = 0.0;
        for (int trial = 0; trial < 6; ++trial) {
            const Eigen::Matrix3f R = RandomRotation(rng).cast<float>();
            const PointCloud rotated = Transformed(cloud, R);
            const double sigma =
                NdtSetDifference(reference, ComputeNdtDescriptorSet(rotated, config));
            EXPECT_LT(sigma, 1.5 * grid_floor) << "trial " << trial;
            sigma_sum += sigma;
            raw_sum +=
                NdtSetDifference(reference_raw, ComputeNdtDescriptorSet(rotated, unnormalised));
        }
        EXPECT_GT(raw_sum, 4.0 * sigma_sum);
    }
}

TEST(NdtDescriptor, RegriddingAgreesWithRotatingCells) {
    const PointCloud cloud = StructuredScan(10);
    NdtConfig config;
    NdtConfig regrid = config;
    regrid.regrid_rotations = true;
    const Eigen::Matrix3f R =
        Eigen::AngleAxisf(0.7f, Eigen::Vector3f(1, 2, 3).normalized()).matrix();
    const PointCloud rotated = Transformed(cloud, R);
    const auto a = ComputeNdtDescriptorSet(rotated, config);
    const auto b = ComputeNdtDescriptorSet(rotated, regrid);
    // Both modes choose their rotations from the same cells, so they pair up one to one; what
    // regridding changes is only which cells the rotated points form.
    ASSERT_EQ(a.descriptors.size(), b.descriptors.size());
    for (std::size_t i = 0; i < a.descriptors.size(); ++i) {
        SCOPED_TRACE(i);
        const NdtDescriptor& turned = a.descriptors[i];
        const NdtDescriptor& regridded = b.descriptors[i];
        EXPECT_TRUE(regridded.R_aligned_sensor.isApprox(turned.R_aligned_sensor, 1e-12));
        // How many cells a plane occupies depends on its angle to the grid (the two totals are
        // 6% apart for this scan), so they agree only to within that.
        EXPECT_NEAR(regridded.total, turned.total, 0.1 * turned.total);
        // Pairwise, not just the best pair: a regrid by the wrong rotation would miss here.
        EXPECT_LT(NdtDifference(turned, regridded), 0.15);
    }
}

TEST(NdtDescriptor, SigmaIsSymmetricAndZeroOnIdenticalInput) {
    const auto a = ComputeNdtDescriptorSet(StructuredScan(11), NdtConfig{});
    const auto b = ComputeNdtDescriptorSet(StructuredScan(12), NdtConfig{});
    EXPECT_EQ(NdtSetDifference(a, a), 0.0);
    EXPECT_EQ(NdtDifference(a.descriptors[0], a.descriptors[0]), 0.0);
    EXPECT_DOUBLE_EQ(NdtSetDifference(a, b), NdtSetDifference(b, a));
    EXPECT_GT(NdtSetDifference(a, b), 0.0);
}

TEST(NdtDescriptor, SigmaMatchesEquationEightByHand) {
    NdtDescriptor f;
    SetNdtCounts(f, 2, 2, {1, 1, 2, 0});
    EXPECT_EQ(f.total, 4.0);
    NdtDescriptor g;
    SetNdtCounts(g, 2, 2, {0, 2, 0, 0});
    // Row 0: |(0.25, -0.75)| = 0.7906; row 1: |(0.5, 0)| = 0.5; times 4/2.
    EXPECT_NEAR(NdtDifference(f, g), (std::sqrt(0.625) + 0.5) * 2.0, 1e-6);
    NdtDescriptor other_shape;
    SetNdtCounts(other_shape, 1, 4, {0, 2, 0, 0});
    EXPECT_THROW(NdtDifference(f, other_shape), ConfigError);
}

// More range rows than one block of kNdtRowBlock compares, in more than one column: each row
// adds its own distance, none is lost at a block border.
TEST(NdtDescriptor, SigmaSumsEveryRowAcrossRowBlocks) {
    const int rows = kNdtRowBlock + 3;
    const int cols = 3;
    std::vector<float> a_counts(static_cast<std::size_t>(rows * cols), 0.0f);
    std::vector<float> b_counts = a_counts;
    double expected = 0.0;
    for (int row = 0; row < rows; ++row) {
        a_counts[static_cast<std::size_t>(row * cols)] = 1.0f;            // (1, 0, 0) in every row
        b_counts[static_cast<std::size_t>(row * cols + row % 3)] = 1.0f;  // (1,0,0), (0,1,0), ...
        expected += row % 3 == 0 ? 0.0 : std::sqrt(2.0) / rows;
    }
    NdtDescriptor a;
    NdtDescriptor b;
    SetNdtCounts(a, rows, cols, a_counts);
    SetNdtCounts(b, rows, cols, b_counts);
    EXPECT_EQ(a.PaddedRows(), 2 * kNdtRowBlock);
    EXPECT_NEAR(NdtDifference(a, b), expected, 1e-6);
    EXPECT_EQ(NdtDifference(a, a), 0.0);
}

TEST(NdtDescriptor, SetCountsRejectsBadCounts) {
    NdtDescriptor f;
    EXPECT_THROW(SetNdtCounts(f, 2, 2, {1, 2, 3}), ConfigError);
    EXPECT_THROW(SetNdtCounts(f, 0, 2, {}), ConfigError);
    EXPECT_THROW(SetNdtCounts(f, 1, 2, {1, -1}), ConfigError);
    EXPECT_THROW(SetNdtCounts(f, 1, 2, {1, std::numeric_limits<float>::quiet_NaN()}), ConfigError);
    EXPECT_THROW(SetNdtCounts(f, 1, 2, {1, std::numeric_limits<float>::infinity()}), ConfigError);
}

TEST(NdtDescriptor, SigmaOfEmptyDescriptors) {
    NdtDescriptor empty;
    SetNdtCounts(empty, 1, 2, {0, 0});
    NdtDescriptor full;
    SetNdtCounts(full, 1, 2, {1, 0});
    EXPECT_EQ(NdtDifference(empty, empty), 0.0);
    EXPECT_EQ(NdtDifference(empty, full), std::numeric_limits<double>::infinity());
    EXPECT_EQ(NdtDifference(full, empty), std::numeric_limits<double>::infinity());
}

TEST(NdtDescriptor, FeatureLayoutFollowsEquationOne) {
    NdtConfig config;
    config.normalise_rotation = false;
    // The centre of class 5, not +z: class 0 is what a classifier returns when it fails.
    const Eigen::Vector3d normal = HalfSpherePartition(9).centres()[5];
    const auto set = ComputeNdtDescriptorSet(PlanePoints(normal, 20000, 13), config);
    ASSERT_EQ(set.descriptors.size(), 1U);
    const NdtDescriptor& f = set.descriptors[0];
    EXPECT_EQ(f.rows, 5);
    EXPECT_EQ(f.cols, 11);
    // Every planar cell has that normal: all planar counts (columns 1-9) in column s + 5 = 6.
    // The rest are linear (column 10): slivers where the tilted patch's rim cuts a cell.
    double planar = 0.0;
    double in_column = 0.0;
    for (int row = 0; row < f.rows; ++row) {
        for (int column = 1; column <= 9; ++column) planar += f.counts[row * f.cols + column];
        in_column += f.counts[row * f.cols + 6];
    }
    EXPECT_EQ(in_column, planar);
    EXPECT_GT(in_column, 0.85 * f.total);
    EXPECT_GT(f.total, 100.0);
}

// Coinciding points far from the sensor: their raw moments cancel to rounding noise (~1e-11 m^2
// at 100 m), which must not pass for a shape with a made-up axis. Found by review: 1000 copies of
// one point gave linear cells, and half the cells were wrong at 500 copies.
TEST(NdtCells, CoincidingPointsAreDegenerateAtAnyDistance) {
    std::mt19937 rng(31);
    std::uniform_real_distribution<float> coordinate(-120.0f, 120.0f);
    int cells = 0;
    for (int copies : {5, 100, 1000, 3000}) {
        for (int trial = 0; trial < 40; ++trial) {
            const Eigen::Vector3f p{coordinate(rng), coordinate(rng), coordinate(rng) / 10.0f};
            for (const NdtCell& cell : ComputeNdtCells(PointCloud(copies, p), 0.5, 5)) {
                ++cells;
                EXPECT_EQ(ClassifyCovariance(cell.covariance_m2, 0.1).shape, CellShape::kDegenerate)
                    << copies << " copies of " << p.transpose();
                EXPECT_LT((cell.mean_m - p.cast<double>()).norm(), 1e-9);
            }
        }
    }
    EXPECT_EQ(cells, 4 * 40 * 8);  // every point lies in 8 cells
    // A real spread a few times the cutoff is still a shape: points 0.025 mm apart along x,
    // 0.5 mm in all (variance 2e-8 m^2 against a cutoff of 4e-9 m^2 here, 130 m out).
    PointCloud thin;
    for (int i = 0; i < 200; ++i) {
        thin.push_back({100.0f + 2.5e-5f * static_cast<float>(i % 20), 80.0f, 10.0f});
    }
    const std::vector<NdtCell> thin_cells = ComputeNdtCells(thin, 0.5, 5);
    ASSERT_FALSE(thin_cells.empty());
    for (const NdtCell& cell : thin_cells) {
        EXPECT_EQ(ClassifyCovariance(cell.covariance_m2, 0.1).shape, CellShape::kLinear);
    }
}

TEST(NdtDescriptor, DegenerateScansGiveDefinedResults) {
    NdtConfig config;
    const PointCloud same(100, Eigen::Vector3f(1, 2, 3));
    EXPECT_THROW(ComputeNdtDescriptorSet(same, config), EmptyInputError);
    EXPECT_THROW(ComputeNdtDescriptorSet({{1, 2, 3}}, config), EmptyInputError);
    EXPECT_THROW(ComputeNdtDescriptorSet({}, config), EmptyInputError);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(ComputeNdtDescriptorSet(PointCloud(50, Eigen::Vector3f(nan, 0, 0)), config),
                 EmptyInputError);
    // Collinear points: only linear cells, no plane to align: one descriptor, no crash.
    PointCloud line;
    for (int i = 0; i < 2000; ++i) line.push_back({0.01f * static_cast<float>(i), 0, 0});
    const auto line_set = ComputeNdtDescriptorSet(line, config);
    EXPECT_EQ(line_set.descriptors.size(), 1U);
    // A single plane: one orientation only, so R_z alone, turning its normal onto z.
    const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.3, 0.2).normalized();
    const auto plane_set = ComputeNdtDescriptorSet(PlanePoints(normal, 20000, 14), config);
    ASSERT_EQ(plane_set.descriptors.size(), 1U);
    EXPECT_NEAR(std::abs((plane_set.descriptors[0].R_aligned_sensor * normal).z()), 1.0, 1e-6);
    // The paper's literal alignment turns the partition line of the normal onto z instead.
    config.align_to_mean_direction = false;
    const auto literal = ComputeNdtDescriptorSet(PlanePoints(normal, 20000, 14), config);
    ASSERT_EQ(literal.descriptors.size(), 1U);
    const HalfSpherePartition partition(9);
    const Eigen::Vector3d normal_line =
        partition.centres()[static_cast<std::size_t>(partition.NearestLine(normal))];
    EXPECT_NEAR(std::abs((literal.descriptors[0].R_aligned_sensor * normal_line).z()), 1.0, 1e-9);
}

// The message of an empty descriptor says why nothing was counted.
std::string EmptyInputMessage(const PointCloud& cloud, const NdtConfig& config) {
    try {
        ComputeNdtDescriptorSet(cloud, config);
    } catch (const EmptyInputError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no EmptyInputError";
    return "";
}

TEST(NdtDescriptor, EmptyInputErrorSaysWhyNothingWasCounted) {
    NdtConfig config;
    const std::string sparse = EmptyInputMessage({{1, 2, 3}}, config);
    EXPECT_NE(sparse.find("fewer than 5 points"), std::string::npos) << sparse;
    const std::string degenerate = EmptyInputMessage(PointCloud(100, {1, 2, 3}), config);
    EXPECT_NE(degenerate.find("degenerate"), std::string::npos) << degenerate;
    EXPECT_EQ(degenerate.find("fewer than"), std::string::npos) << degenerate;
    // A blob has only spherical cells; with s = l = 0 their class is not counted.
    config.spherical_classes = 0;
    config.linear_classes = 0;
    const std::string disabled = EmptyInputMessage(test::RandomCloud(20000, 7, 0.2f), config);
    EXPECT_NE(disabled.find("disabled"), std::string::npos) << disabled;
    EXPECT_NE(disabled.find("s = 0"), std::string::npos) << disabled;
    EXPECT_EQ(disabled.find("fewer than"), std::string::npos) << disabled;
    EXPECT_EQ(disabled.find("degenerate"), std::string::npos) << disabled;
    EXPECT_EQ(disabled.find("could be classified"), std::string::npos) << disabled;
}

TEST(NdtConfig, DefaultsAreThePapersAndAbsurdValuesAreRejected) {
    NdtConfig config;
    EXPECT_NO_THROW(config.Validate());
    EXPECT_EQ(config.FeatureCount(), 11);
    EXPECT_EQ(config.RangeCount(), 5);
    const auto invalid = [](auto mutate) {
        NdtConfig c;
        mutate(c);
        EXPECT_THROW(c.Validate(), ConfigError);
    };
    invalid([](NdtConfig& c) { c.cell_size_m = 0; });
    invalid([](NdtConfig& c) { c.min_points_per_cell = 2; });
    invalid([](NdtConfig& c) { c.eigen_ratio_threshold = 1.0; });
    invalid([](NdtConfig& c) { c.spherical_classes = c.planar_classes = c.linear_classes = 0; });
    invalid([](NdtConfig& c) { c.planar_classes = -1; });
    invalid([](NdtConfig& c) { c.range_limits_m = {3, 3}; });
    invalid([](NdtConfig& c) { c.range_limits_m = {-1}; });
    invalid([](NdtConfig& c) { c.ambiguity_ratio = 1.5; });
}

}  // namespace
}  // namespace lidarloop::core

namespace lidarloop::core {
namespace {

TEST(Eigen3x3, MatchesEigensIterativeSolverOnRandomCovariances) {
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> log_scale(-4.0, 1.0);
    for (int trial = 0; trial < 2000; ++trial) {
        // Random orientation, eigenvalues spread over 5 decades: planes, lines, blobs.
        const Eigen::Matrix3d R = RandomRotation(rng);
        const Eigen::Vector3d lambda{std::pow(10.0, log_scale(rng)), std::pow(10.0, log_scale(rng)),
                                     std::pow(10.0, log_scale(rng))};
        const Eigen::Matrix3d a = R * lambda.asDiagonal() * R.transpose();
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> reference(a);
        const Eigen::Vector3d expected = reference.eigenvalues().reverse();
        const Eigen::Vector3d actual = SymmetricEigenvaluesDescending(a);
        EXPECT_LT((actual - expected).cwiseAbs().maxCoeff(), 1e-8 * expected[0]) << a;
        for (int k : {0, 2}) {
            const bool separated = std::abs(expected[k] - expected[1]) > 0.05 * expected[0];
            if (!separated) continue;
            const Eigen::Vector3d v = SymmetricEigenvector(a, actual[k]);
            EXPECT_NEAR(std::abs(v.dot(reference.eigenvectors().col(2 - k))), 1.0, 1e-9) << a;
        }
    }
}

TEST(Eigen3x3, DiagonalAndRepeatedEigenvalues) {
    EXPECT_EQ(SymmetricEigenvaluesDescending(Eigen::Vector3d(1, 3, 2).asDiagonal()),
              Eigen::Vector3d(3, 2, 1));
    const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
    EXPECT_LT((SymmetricEigenvaluesDescending(identity) - Eigen::Vector3d::Ones()).norm(), 1e-15);
    const Eigen::Vector3d v = SymmetricEigenvector(identity, 1.0);  // any unit vector will do
    EXPECT_NEAR(v.norm(), 1.0, 1e-12);
    Eigen::Matrix3d plane = Eigen::Vector3d(1, 1, 0).asDiagonal();
    EXPECT_NEAR(std::abs(SymmetricEigenvector(plane, 0.0).z()), 1.0, 1e-12);
}

}  // namespace
}  // namespace lidarloop::core

// The rotation normalisation of the NDT descriptor (Magnusson et al. 2009, section II-C) and the
// layout of its matrix (eqs. 1-3) on scenes whose answer is known by construction.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarloop/core/ndt/ndt_cells.hpp"
#include "lidarloop/core/ndt/ndt_descriptor.hpp"
#include "lidarloop/core/ndt/ndt_shape.hpp"
#include "lidarloop/core/ndt/sphere_partition.hpp"
#include "test_utils.hpp"

namespace lidarloop::core {
namespace {

using test::RandomRotation;
using test::Transformed;

// A rectangle through `centre` with normal `normal`, sides 2 half_u x 2 half_v, sampled at
// `per_m2` points per square metre, with Gaussian noise of `noise_m` along the normal (so that
// the cells' normals scatter a little, like a real surface's).
struct Patch {
    Eigen::Vector3d centre;
    Eigen::Vector3d normal;
    double half_u = 3.0;
    double half_v = 3.0;
};

void AddPatch(const Patch& patch, double per_m2, unsigned seed, PointCloud& cloud,
              double noise_m = 0.01) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::normal_distribution<double> noise(0.0, noise_m);
    const Eigen::Vector3d n = patch.normal.normalized();
    // A horizontal in-plane side where there is one, so that walls are sampled upright.
    const Eigen::Vector3d side =
        std::abs(n.z()) > 0.99 ? n.unitOrthogonal() : Eigen::Vector3d::UnitZ().cross(n);
    const Eigen::Vector3d a = side.normalized();
    const Eigen::Vector3d b = n.cross(a);
    const int count = static_cast<int>(per_m2 * 4.0 * patch.half_u * patch.half_v);
    for (int i = 0; i < count; ++i) {
        const double along_a = u(rng) * patch.half_u;
        const double along_b = u(rng) * patch.half_v;
        const Eigen::Vector3d p = patch.centre + along_a * a + along_b * b + noise(rng) * n;
        cloud.push_back(p.cast<float>());
    }
}

// The horizontal unit vector at `longitude_deg` from +x.
Eigen::Vector3d Horizontal(double longitude_deg) {
    const double a = longitude_deg * std::numbers::pi / 180.0;
    return {std::cos(a), std::sin(a), 0.0};
}

// Reference for the sign rule: the mean of the classified cells' means (what the descriptor
// orients lines against), computed cell by cell.
Eigen::Vector3d ClassifiedCentroid(const PointCloud& cloud, const NdtConfig& config) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (const NdtCell& cell :
         ComputeNdtCells(cloud, config.cell_size_m, config.min_points_per_cell)) {
        if (ClassifyCovariance(cell.covariance_m2, config.eigen_ratio_threshold).shape ==
            CellShape::kDegenerate) {
            continue;
        }
        sum += cell.mean_m;
        ++count;
    }
    return sum / count;
}

// The line `line` given the sign that points against `centroid`.
Eigen::Vector3d AgainstCentroid(const Eigen::Vector3d& line, const Eigen::Vector3d& centroid) {
    return line.dot(centroid) > 0.0 ? Eigen::Vector3d(-line) : line;
}

double CountAt(const NdtDescriptor& f, int row, int column) {
    return f.counts[static_cast<std::size_t>(row * f.cols + column)];
}

double RowSum(const NdtDescriptor& f, int row) {
    double sum = 0.0;
    for (int column = 0; column < f.cols; ++column) sum += CountAt(f, row, column);
    return sum;
}

// A plane whose normal lies on the border between two orientation classes splits its cells
// between both, so both become peaks of Z. They are one plane: one first direction, no second
// (a second direction a few degrees from the first would set the yaw from noise).
TEST(NdtRotation, PlaneOnAClassBorderGivesOneDescriptor) {
    const HalfSpherePartition partition(9);
    const auto& c = partition.centres();
    // Lines are compared up to sign, so every horizontal normal lies on the border between a
    // sector and the sector opposite it (1 and 5 at 22.5 degrees): every upright wall splits.
    const std::vector<Eigen::Vector3d> borders = {
        (c[0] + c[1]).normalized(),  // polar cap | sector 1
        (c[1] + c[2]).normalized(),  // sectors 1 | 2
        Horizontal(22.5),            // sectors 1 | 5
        Eigen::Vector3d::UnitX(),    // sectors 1 | 4 | 5 | 8
    };
    for (const Eigen::Vector3d& normal : borders) {
        SCOPED_TRACE(normal.transpose());
        // Two or more lines are equally near: the normal is on their Voronoi border.
        const int nearest = partition.NearestLine(normal);
        int ties = 0;
        for (const auto& centre : c) {
            ties +=
                std::abs(std::abs(centre.dot(normal)) - std::abs(c[nearest].dot(normal))) < 1e-12;
        }
        ASSERT_GE(ties, 2);
        PointCloud cloud;
        AddPatch({5.0 * normal + 2.0 * normal.unitOrthogonal(), normal}, 600.0, 21, cloud);
        const NdtDescriptorSet set = ComputeNdtDescriptorSet(cloud, NdtConfig{});
        ASSERT_EQ(set.descriptors.size(), 1U);
        EXPECT_NEAR(std::abs((set.descriptors[0].R_aligned_sensor * normal).z()), 1.0, 1e-4);
    }
}

// A direction on the sphere: colatitude from +z and longitude from +x, degrees.
Eigen::Vector3d UnitDirection(double colatitude_deg, double longitude_deg) {
    const double colatitude = colatitude_deg * std::numbers::pi / 180.0;
    return std::sin(colatitude) * Horizontal(longitude_deg) +
           std::cos(colatitude) * Eigen::Vector3d::UnitZ();
}

// Two planes 16 degrees apart, in different classes (the polar cap and sector 1), the second too
// small to be ambiguous with the first: it is Y's only peak, but too close to the first to set a
// yaw. R_z alone is used, the rotation about an axis perpendicular to both the first line and z.
TEST(NdtRotation, SecondDirectionNearlyParallelToTheFirstSetsNoYaw) {
    const HalfSpherePartition partition(9);
    const Eigen::Vector3d a = UnitDirection(20.0, 22.5);
    const Eigen::Vector3d b = UnitDirection(36.0, 22.5);
    ASSERT_EQ(partition.NearestLine(a), 0);
    ASSERT_EQ(partition.NearestLine(b), 1);
    PointCloud cloud;
    AddPatch({6.0 * a, a, 3.0, 3.0}, 600.0, 24, cloud);
    AddPatch({12.0 * b, b, 2.0, 2.0}, 600.0, 25, cloud);
    const NdtDescriptorSet set = ComputeNdtDescriptorSet(cloud, NdtConfig{});
    ASSERT_EQ(set.descriptors.size(), 1U);
    const Eigen::Matrix3d& R = set.descriptors[0].R_aligned_sensor;
    EXPECT_GT(std::abs((R * a).z()), 0.999);  // to within the grid's pull on the normals
    EXPECT_NEAR(Eigen::AngleAxisd(R).axis().z(), 0.0, 1e-9);
}

// A floor and one wall: R_z turns the floor's normal onto z, R_y the wall's normal into the yz
// plane, on the +y side for the sign that points against the centroid of the cells.
TEST(NdtRotation, FloorAndOneWallPutTheWallNormalOnPlusY) {
    for (double longitude_deg : {0.0, 22.5, 37.0, 100.0}) {  // on a class border and off
        SCOPED_TRACE(longitude_deg);
        const Eigen::Vector3d wall_normal = Horizontal(longitude_deg);
        PointCloud cloud;
        AddPatch({{1.0, 1.0, -1.7}, Eigen::Vector3d::UnitZ(), 9.0, 9.0}, 300.0, 22, cloud);
        AddPatch({7.0 * wall_normal + Eigen::Vector3d(0, 0, 0.3), wall_normal, 8.0, 2.0}, 300.0, 23,
                 cloud);
        const NdtConfig config;
        const Eigen::Vector3d centroid = ClassifiedCentroid(cloud, config);
        const Eigen::Vector3d c = centroid.normalized();
        // Both lines are far from perpendicular to the centroid: one sign each, one descriptor.
        ASSERT_GT(std::abs(c.z()), 0.15);
        ASSERT_GT(std::abs(c.dot(wall_normal)), 0.15);
        const NdtDescriptorSet set = ComputeNdtDescriptorSet(cloud, config);
        ASSERT_EQ(set.descriptors.size(), 1U);
        const Eigen::Matrix3d& R = set.descriptors[0].R_aligned_sensor;
        EXPECT_NEAR((R * AgainstCentroid(Eigen::Vector3d::UnitZ(), c)).z(), 1.0, 1e-4);
        const Eigen::Vector3d wall = R * AgainstCentroid(wall_normal, c);
        // Not exact: cell borders cut the noise about a surface obliquely, which pulls the cells'
        // normals a few tenths of a degree towards the grid's axes.
        EXPECT_NEAR(wall.x(), 0.0, 0.02);
        EXPECT_NEAR(wall.y(), 1.0, 1e-4);
    }
}

// A floor in front of two equally large walls at right angles: Z = {floor}, Y = {wall A, wall B}.
// Each wall's normal is horizontal, so on the border between a sector and the one opposite it;
// its two halves are merged into one peak. One descriptor per wall.
PointCloud CornerScene(double wall_b_half_length_m) {
    PointCloud cloud;
    const Eigen::Vector3d a = Horizontal(22.5);
    const Eigen::Vector3d b = Horizontal(112.5);
    AddPatch({{2.0, 3.0, -1.7}, Eigen::Vector3d::UnitZ(), 9.0, 9.0}, 300.0, 31, cloud);
    AddPatch({7.0 * a + 2.0 * b + Eigen::Vector3d(0, 0, 0.3), a, 6.0, 2.0}, 300.0, 32, cloud);
    AddPatch({7.0 * b + 2.0 * a + Eigen::Vector3d(0, 0, 0.3), b, wall_b_half_length_m, 2.0}, 300.0,
             33, cloud);
    return cloud;
}

TEST(NdtRotation, TwoEqualWallsAtRightAnglesGiveOneDescriptorEach) {
    const PointCloud cloud = CornerScene(6.0);
    const NdtConfig config;
    const Eigen::Vector3d c = ClassifiedCentroid(cloud, config).normalized();
    const Eigen::Vector3d walls[] = {Horizontal(22.5), Horizontal(112.5)};
    for (const Eigen::Vector3d& line :
         {Eigen::Vector3d(Eigen::Vector3d::UnitZ()), walls[0], walls[1]}) {
        ASSERT_GT(std::abs(c.dot(line)), 0.15) << "a sign would be ambiguous: " << line.transpose();
    }
    const NdtDescriptorSet set = ComputeNdtDescriptorSet(cloud, config);
    ASSERT_EQ(set.descriptors.size(), 2U);
    std::vector<int> aligned_wall;
    for (const NdtDescriptor& f : set.descriptors) {
        const Eigen::Matrix3d& R = f.R_aligned_sensor;
        EXPECT_NEAR((R * AgainstCentroid(Eigen::Vector3d::UnitZ(), c)).z(), 1.0, 1e-4);
        for (int w = 0; w < 2; ++w) {
            if ((R * AgainstCentroid(walls[w], c)).y() > 0.999) aligned_wall.push_back(w);
        }
    }
    std::sort(aligned_wall.begin(), aligned_wall.end());
    EXPECT_EQ(aligned_wall, (std::vector<int>{0, 1}));
}

// t_a = 0 makes every class ambiguous with the highest: Z must still hold only classes that
// have cells (an empty class has no direction). t_a = 1 keeps only the unambiguous peaks.
TEST(NdtRotation, AmbiguityRatioOfZeroAndOneGiveDefinedSets) {
    const PointCloud cloud = CornerScene(4.0);  // wall B shorter: the second peak is wall A
    NdtConfig config;
    const Eigen::Vector3d c = ClassifiedCentroid(cloud, config).normalized();
    config.ambiguity_ratio = 1.0;
    const NdtDescriptorSet strict = ComputeNdtDescriptorSet(cloud, config);
    ASSERT_EQ(strict.descriptors.size(), 1U);
    const Eigen::Matrix3d& R = strict.descriptors[0].R_aligned_sensor;
    EXPECT_NEAR((R * AgainstCentroid(Eigen::Vector3d::UnitZ(), c)).z(), 1.0, 1e-4);
    EXPECT_NEAR((R * AgainstCentroid(Horizontal(22.5), c)).y(), 1.0, 1e-4);
    // t_a = 0: every occupied class is a first direction. Those are the floor and the two walls
    // (each wall's halves, split by the equator, merged), each paired with the other two.
    config.ambiguity_ratio = 0.0;
    const NdtDescriptorSet all = ComputeNdtDescriptorSet(cloud, config);
    ASSERT_EQ(all.descriptors.size(), 6U);
    const Eigen::Vector3d normals[] = {Eigen::Vector3d::UnitZ(), Horizontal(22.5),
                                       Horizontal(112.5)};
    for (const NdtDescriptor& f : all.descriptors) {
        int on_z = 0;
        int on_y = 0;
        for (const Eigen::Vector3d& n : normals) {
            on_z += std::abs((f.R_aligned_sensor * n).z()) > 0.999;
            on_y += std::abs((f.R_aligned_sensor * n).y()) > 0.999;
        }
        EXPECT_EQ(on_z, 1);
        EXPECT_EQ(on_y, 1);
        EXPECT_EQ(f.total, strict.descriptors[0].total);
    }
}

// A scan symmetric about the sensor has its centroid at the sensor, up to sampling noise: the
// centroid's direction is noise and must not pick the signs. Both signs of both lines are kept.
PointCloud SymmetricRoom() {
    PointCloud cloud;
    const double per_m2 = 150.0;
    unsigned seed = 41;
    for (double side : {-1.0, 1.0}) {
        AddPatch({{0, 0, 2.0 * side}, Eigen::Vector3d::UnitZ(), 10.0, 5.0}, per_m2, seed++, cloud);
        AddPatch({{0, 5.0 * side, 0}, Eigen::Vector3d::UnitY(), 10.0, 2.0}, per_m2, seed++, cloud);
        AddPatch({{10.0 * side, 0, 0}, Eigen::Vector3d::UnitX(), 5.0, 2.0}, per_m2, seed++, cloud);
    }
    return cloud;
}

// Whether `set`, computed from the room turned by `R_scan_room`, holds a descriptor that aligns
// the room like `R_aligned_room` does, to within `tolerance_rad`.
bool HasAlignment(const NdtDescriptorSet& set, const Eigen::Matrix3d& R_scan_room,
                  const Eigen::Matrix3d& R_aligned_room, double tolerance_rad) {
    return std::any_of(set.descriptors.begin(), set.descriptors.end(), [&](const NdtDescriptor& f) {
        const Eigen::Matrix3d difference =
            f.R_aligned_sensor * R_scan_room * R_aligned_room.transpose();
        return Eigen::AngleAxisd(difference).angle() < tolerance_rad;
    });
}

TEST(NdtRotation, ScanSymmetricAboutTheSensorKeepsBothSigns) {
    const PointCloud room = SymmetricRoom();
    const NdtConfig config;
    const NdtDescriptorSet reference = ComputeNdtDescriptorSet(room, config);
    EXPECT_EQ(reference.descriptors.size(), 4U);  // (+-z of the floor) x (+-y of the long walls)
    // Every rotated copy is aligned in all the ways the room is (to 2 degrees: the grid's pull on
    // the normals). A sign picked by the centroid's noisy direction misses half of them.
    std::mt19937 rng(42);
    for (int trial = 0; trial < 6; ++trial) {
        SCOPED_TRACE(trial);
        const Eigen::Matrix3d R = RandomRotation(rng);
        const NdtDescriptorSet rotated =
            ComputeNdtDescriptorSet(Transformed(room, R.cast<float>()), config);
        for (const NdtDescriptor& f : reference.descriptors) {
            EXPECT_TRUE(HasAlignment(rotated, R, f.R_aligned_sensor, 2.0 * std::numbers::pi / 180))
                << f.R_aligned_sensor;
        }
    }
    // A quarter turn maps the grid onto itself, so nothing but the alignment differs: sigma' ~ 0.
    Eigen::Matrix3d quarter;
    quarter << 1, 0, 0, 0, 0, -1, 0, 1, 0;
    const NdtDescriptorSet turned =
        ComputeNdtDescriptorSet(Transformed(room, quarter.cast<float>()), config);
    EXPECT_LT(NdtSetDifference(reference, turned), 1e-6);
}

// s spherical sub-classes split [t_e, 1] of l2/l1 into s equal bands. A box of sides a x b x b
// has l2/l1 = (b/a)^2; each lies inside one half-cell voxel, so every cell that holds any of
// its points holds all of them, and all those cells have that ratio.
TEST(NdtLayout, SphericalSubClassesFollowTheirBand) {
    NdtConfig config;
    config.spherical_classes = 3;  // bands [0.1, 0.4), [0.4, 0.7), [0.7, 1]
    config.cell_size_m = 1.0;      // voxels of 0.5 m
    // 0.37 is in band 0 only if the bands start at t_e, not at 0.
    const double ratios[] = {0.37, 0.55, 0.9};
    const double centres_x[] = {1.25, 4.25, 7.25};  // ranges in rows 0, 1, 2
    std::mt19937 rng(51);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    PointCloud cloud;
    for (int k = 0; k < 3; ++k) {
        const double a = 0.2;
        const double b = a * std::sqrt(ratios[k]);
        for (int i = 0; i < 3000; ++i) {
            cloud.push_back(
                Eigen::Vector3d{centres_x[k] + a * u(rng), 0.25 + b * u(rng), 0.25 + b * u(rng)}
                    .cast<float>());
        }
    }
    const NdtDescriptorSet set = ComputeNdtDescriptorSet(cloud, config);
    ASSERT_EQ(set.descriptors.size(), 1U);  // no plane, nothing to align
    const NdtDescriptor& f = set.descriptors[0];
    for (int k = 0; k < 3; ++k) {
        SCOPED_TRACE(k);
        EXPECT_EQ(CountAt(f, k, k), 8.0);  // the 8 cells around the box's voxel
        EXPECT_EQ(RowSum(f, k), 8.0);
    }
    EXPECT_EQ(f.total, 24.0);
}

// The row of a cell is the interval of R that holds the distance from the sensor to its mean.
TEST(NdtLayout, RangeRowFollowsTheCellMean) {
    const NdtConfig config;  // R = {[0,3), [3,6), [6,9), [9,15), [15,inf)}
    const double ranges_m[] = {1.8, 4.5, 7.5, 12.0, 25.0};
    for (int row = 0; row < 5; ++row) {
        SCOPED_TRACE(row);
        PointCloud cloud;
        const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.5, 0.3).normalized();
        AddPatch({ranges_m[row] * normal, normal, 0.4, 0.4}, 3000.0, 52, cloud);
        const NdtDescriptorSet set = ComputeNdtDescriptorSet(cloud, config);
        const NdtDescriptor& f = set.descriptors[0];
        EXPECT_GT(f.total, 0.0);
        EXPECT_EQ(RowSum(f, row), f.total);
    }
}

// A cell whose mean is exactly on a border belongs to the upper interval, [6, 9) here. A grid
// of points in the plane x = 6, symmetric about the x axis, gives a cell with mean exactly
// (6, 0, 0); every other cell holding these points is farther out.
TEST(NdtLayout, CellMeanOnARangeBorderGoesToTheUpperInterval) {
    PointCloud cloud;
    for (int i = -4; i < 4; ++i) {
        for (int j = -4; j < 4; ++j) {
            cloud.push_back({6.0f, (static_cast<float>(i) + 0.5f) * 0.0625f,
                             (static_cast<float>(j) + 0.5f) * 0.0625f});
        }
    }
    const NdtConfig config;
    bool mean_on_border = false;
    for (const NdtCell& cell : ComputeNdtCells(cloud, config.cell_size_m, 5)) {
        mean_on_border |= cell.mean_m.squaredNorm() == 36.0;
    }
    ASSERT_TRUE(mean_on_border) << "the test would prove nothing";
    const NdtDescriptorSet set = ComputeNdtDescriptorSet(cloud, config);
    const NdtDescriptor& f = set.descriptors[0];
    EXPECT_EQ(RowSum(f, 1), 0.0);
    EXPECT_EQ(RowSum(f, 2), f.total);
}

// Class counts other than the paper's: no spherical class, one planar class (nothing to align
// by orientation), no linear class, several linear classes.
TEST(NdtLayout, UnusualClassCountsKeepTheMatrixShape) {
    PointCloud cloud;
    AddPatch({{1.0, 1.0, -1.7}, Eigen::Vector3d::UnitZ(), 9.0, 9.0}, 200.0, 61, cloud);
    AddPatch({{6.0, 0.0, 0.0}, Eigen::Vector3d::UnitX(), 8.0, 2.0}, 200.0, 62, cloud);
    AddPatch({{-3.0, 5.0, 0.0}, Horizontal(60.0), 6.0, 2.0}, 200.0, 63, cloud);
    for (int i = 0; i < 3000; ++i) {  // a pole
        cloud.push_back({2.0f, -4.0f, -1.7f + 0.0015f * static_cast<float>(i)});
    }
    const auto shape = [](int s, int p, int l) {
        NdtConfig config;
        config.spherical_classes = s;
        config.planar_classes = p;
        config.linear_classes = l;
        return config;
    };
    for (const NdtConfig& config :
         {shape(0, 9, 1), shape(1, 1, 1), shape(1, 9, 0), shape(1, 9, 3), shape(0, 1, 0)}) {
        SCOPED_TRACE(testing::Message() << "s=" << config.spherical_classes << " p="
                                        << config.planar_classes << " l=" << config.linear_classes);
        const NdtDescriptorSet set = ComputeNdtDescriptorSet(cloud, config);
        ASSERT_FALSE(set.descriptors.empty());
        for (const NdtDescriptor& f : set.descriptors) {
            EXPECT_EQ(f.rows, 5);
            EXPECT_EQ(f.cols, config.FeatureCount());
            EXPECT_EQ(f.counts.size(), static_cast<std::size_t>(5 * config.FeatureCount()));
            EXPECT_EQ(f.PaddedRows(), kNdtRowBlock);
            EXPECT_EQ(f.normalised.size(),
                      static_cast<std::size_t>(kNdtRowBlock * config.FeatureCount()));
            EXPECT_GT(f.total, 0.0);
            EXPECT_EQ(NdtDifference(f, f), 0.0);
        }
    }
}

}  // namespace
}  // namespace lidarloop::core

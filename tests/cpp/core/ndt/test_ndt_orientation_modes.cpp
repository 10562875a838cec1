// The orientation modes that steer the NDT rotation normalisation: clusters of lines with known
// directions, brute-force window counts, rotation and sign invariance, bad input.
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/ndt/ndt_orientation_modes.hpp"
#include "test_utils.hpp"

namespace lidarloop::core {
namespace {

constexpr double kWindowRad = 20.0 * std::numbers::pi / 180.0;
constexpr double kDegree = std::numbers::pi / 180.0;

// Lines as the float columns FindOrientationModes reads.
struct Lines {
    std::vector<float> x, y, z;

    void Add(const Eigen::Vector3d& v) {
        x.push_back(static_cast<float>(v.x()));
        y.push_back(static_cast<float>(v.y()));
        z.push_back(static_cast<float>(v.z()));
    }
    std::size_t size() const { return x.size(); }
    Eigen::Vector3d Line(std::size_t i) const { return Eigen::Vector3d(x[i], y[i], z[i]); }
    std::vector<OrientationMode> Modes(double window_rad = kWindowRad) const {
        return FindOrientationModes(x, y, z, window_rad);
    }
};

Eigen::Vector3d Direction(double colatitude_deg, double longitude_deg) {
    const double c = colatitude_deg * kDegree;
    const double l = longitude_deg * kDegree;
    return {std::sin(c) * std::cos(l), std::sin(c) * std::sin(l), std::cos(c)};
}

// `count` lines scattered about `centre` by a Gaussian of `spread_deg` per axis, each given a
// random sign (a line's sign carries nothing).
void AddCluster(const Eigen::Vector3d& centre, int count, double spread_deg, std::mt19937& rng,
                Lines& lines) {
    std::normal_distribution<double> angle(0.0, spread_deg * kDegree);
    std::bernoulli_distribution flip(0.5);
    const Eigen::Vector3d a = centre.unitOrthogonal();
    const Eigen::Vector3d b = centre.cross(a);
    for (int i = 0; i < count; ++i) {
        const double along_a = angle(rng);
        const Eigen::Vector3d v = (centre + along_a * a + angle(rng) * b).normalized();
        lines.Add(flip(rng) ? Eigen::Vector3d(-v) : v);
    }
}

void AddUniform(int count, std::mt19937& rng, Lines& lines) {
    std::normal_distribution<double> normal(0.0, 1.0);
    for (int i = 0; i < count; ++i) {
        lines.Add(Eigen::Vector3d{normal(rng), normal(rng), normal(rng)}.normalized());
    }
}

double AngleBetweenLines(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized()))));
}

// Brute force: the lines within `window_rad` of `line`, and the principal axis of their scatter.
struct WindowContents {
    std::size_t count = 0;
    Eigen::Vector3d principal_axis = Eigen::Vector3d::Zero();
};

WindowContents BruteForceWindow(const Lines& lines, const Eigen::Vector3d& line,
                                double window_rad) {
    WindowContents contents;
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const Eigen::Vector3d v = lines.Line(i).normalized();
        if (std::abs(v.dot(line)) < std::cos(window_rad)) continue;
        ++contents.count;
        scatter += v * v.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
    contents.principal_axis = solver.eigenvectors().col(2);
    return contents;
}

// Three surfaces of different size, at least 45 degrees apart, over a background of noise.
Lines ThreeClustersWithNoise(unsigned seed) {
    std::mt19937 rng(seed);
    Lines lines;
    AddCluster(Direction(3.0, 10.0), 3000, 2.0, rng, lines);    // a floor
    AddCluster(Direction(90.0, 30.0), 2000, 3.0, rng, lines);   // a wall
    AddCluster(Direction(80.0, 125.0), 1000, 4.0, rng, lines);  // another, slightly leaning
    AddUniform(600, rng, lines);
    return lines;
}

// Seed 3 puts a window of noise 22 degrees from the first wall, where it reaches into the wall's
// flank: 533 lines, nearly all the wall's. That shoulder is no peak (its core holds few).
TEST(OrientationModes, ClustersGiveOneModeEachAtTheirNormals) {
    for (unsigned seed = 1; seed <= 5; ++seed) {
        SCOPED_TRACE(seed);
        const Lines lines = ThreeClustersWithNoise(seed);
        const std::vector<OrientationMode> modes = lines.Modes();
        ASSERT_EQ(modes.size(), 3U);  // no mode of the noise, nor of a window on a surface's flank
        const std::vector<Eigen::Vector3d> centres = {Direction(3.0, 10.0), Direction(90.0, 30.0),
                                                      Direction(80.0, 125.0)};
        const std::vector<std::size_t> sizes = {3000, 2000, 1000};
        for (std::size_t k = 0; k < modes.size(); ++k) {
            SCOPED_TRACE(k);
            EXPECT_LT(AngleBetweenLines(modes[k].line, centres[k]), 0.5 * kDegree);
            EXPECT_GE(modes[k].line.z(), 0.0);
            EXPECT_NEAR(modes[k].line.norm(), 1.0, 1e-12);
            // The cluster plus the noise that falls into the window (~6% of 600).
            EXPECT_GE(modes[k].count, sizes[k]);
            EXPECT_LE(modes[k].count, sizes[k] + 80);
        }
    }
}

// Whatever bins the search skips or takes whole, a mode's count is the number of lines within
// the window around it, and its line is where mean shift with half the window stands still.
TEST(OrientationModes, CountsAndLinesMatchBruteForceWindows) {
    for (unsigned seed = 1; seed <= 4; ++seed) {
        SCOPED_TRACE(seed);
        const Lines lines = ThreeClustersWithNoise(seed);
        for (const OrientationMode& mode : lines.Modes()) {
            EXPECT_EQ(mode.count, BruteForceWindow(lines, mode.line, kWindowRad).count);
            const Eigen::Vector3d fixed_point =
                BruteForceWindow(lines, mode.line, 0.5 * kWindowRad).principal_axis;
            EXPECT_LT(AngleBetweenLines(fixed_point, mode.line), 1e-6);
        }
    }
}

// Rotating every line rotates every mode; the partition's classes, fixed in the frame, do not.
TEST(OrientationModes, RotatingTheLinesRotatesTheModes) {
    const Lines lines = ThreeClustersWithNoise(5);
    const std::vector<OrientationMode> modes = lines.Modes();
    std::mt19937 rng(6);
    for (int trial = 0; trial < 10; ++trial) {
        SCOPED_TRACE(trial);
        const Eigen::Matrix3d R = test::RandomRotation(rng);
        Lines rotated;
        for (std::size_t i = 0; i < lines.size(); ++i) rotated.Add(R * lines.Line(i));
        const std::vector<OrientationMode> turned = rotated.Modes();
        ASSERT_EQ(turned.size(), modes.size());
        for (std::size_t k = 0; k < modes.size(); ++k) {
            EXPECT_LT(AngleBetweenLines(turned[k].line, R * modes[k].line), 1e-5);
            // A line within float rounding of a window's rim may fall either side of it.
            EXPECT_NEAR(static_cast<double>(turned[k].count), static_cast<double>(modes[k].count),
                        2.0);
        }
    }
}

TEST(OrientationModes, SignOfEachLineDoesNotMatter) {
    const Lines lines = ThreeClustersWithNoise(7);
    Lines flipped;
    for (std::size_t i = 0; i < lines.size(); ++i) {
        flipped.Add(i % 3 == 0 ? Eigen::Vector3d(-lines.Line(i)) : lines.Line(i));
    }
    const std::vector<OrientationMode> a = lines.Modes();
    const std::vector<OrientationMode> b = flipped.Modes();
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
        EXPECT_EQ(a[k].count, b[k].count);
        EXPECT_LT(AngleBetweenLines(a[k].line, b[k].line), 1e-9);
    }
}

// Two planes 16 degrees apart fall into one window: one mode, on the stronger plane's normal
// (the half window settles there), not on the mean line between them.
TEST(OrientationModes, SurfacesCloserThanTheWindowGiveOneModeOnTheStronger) {
    std::mt19937 rng(8);
    Lines lines;
    const Eigen::Vector3d strong = Direction(20.0, 22.5);
    const Eigen::Vector3d weak = Direction(36.0, 22.5);
    AddCluster(strong, 3000, 1.0, rng, lines);
    AddCluster(weak, 1200, 1.0, rng, lines);
    const std::vector<OrientationMode> modes = lines.Modes();
    ASSERT_EQ(modes.size(), 1U);
    EXPECT_LT(AngleBetweenLines(modes[0].line, strong), 0.3 * kDegree);
    EXPECT_EQ(modes[0].count, 4200U);
}

// A scan of open ground: 90% of the normals point up, two walls hold 5% each. Measured against
// an even spread of all normals the walls would be noise (a window holds 6% of an even spread),
// and the scan would lose its second direction, so its yaw; against the normals the ground does
// not explain, they are the peaks they are. A few stray normals (under 1%) are not.
TEST(OrientationModes, WallsBesideADominantGroundAreModes) {
    std::mt19937 rng(11);
    Lines lines;
    AddCluster(Eigen::Vector3d::UnitZ(), 3600, 2.0, rng, lines);
    AddCluster(Direction(90.0, 15.0), 200, 2.0, rng, lines);
    AddCluster(Direction(88.0, 110.0), 200, 2.0, rng, lines);
    AddCluster(Direction(45.0, 250.0), 30, 2.0, rng, lines);  // 0.7%: stray cells
    const std::vector<OrientationMode> modes = lines.Modes();
    ASSERT_EQ(modes.size(), 3U);
    EXPECT_LT(AngleBetweenLines(modes[0].line, Eigen::Vector3d::UnitZ()), 0.5 * kDegree);
    EXPECT_EQ(modes[1].count, 200U);
    EXPECT_EQ(modes[2].count, 200U);
    const double wall_a = AngleBetweenLines(modes[1].line, Direction(90.0, 15.0));
    const double wall_b = AngleBetweenLines(modes[1].line, Direction(88.0, 110.0));
    EXPECT_LT(std::min(wall_a, wall_b), 0.5 * kDegree);
}

// A cluster straddling the equator (lines with z of both signs) is one mode, not two halves.
TEST(OrientationModes, ClusterOnTheEquatorIsOneMode) {
    std::mt19937 rng(9);
    Lines lines;
    AddCluster(Direction(90.0, 70.0), 2000, 3.0, rng, lines);
    const std::vector<OrientationMode> modes = lines.Modes();
    ASSERT_EQ(modes.size(), 1U);
    EXPECT_EQ(modes[0].count, 2000U);
    EXPECT_LT(AngleBetweenLines(modes[0].line, Direction(90.0, 70.0)), 0.5 * kDegree);
}

TEST(OrientationModes, EmptyAndUnusableLinesGiveNoModes) {
    EXPECT_TRUE(Lines{}.Modes().empty());
    Lines unusable;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    unusable.x = {0.0f, nan, inf, 1.0f};
    unusable.y = {0.0f, 0.0f, 0.0f, nan};
    unusable.z = {0.0f, 1.0f, 0.0f, 0.0f};
    EXPECT_TRUE(unusable.Modes().empty());
    // Unusable lines mixed into a cluster change nothing.
    std::mt19937 rng(10);
    Lines cluster;
    AddCluster(Eigen::Vector3d::UnitZ(), 500, 2.0, rng, cluster);
    const std::vector<OrientationMode> clean = cluster.Modes();
    for (std::size_t i = 0; i < unusable.size(); ++i) {
        cluster.x.push_back(unusable.x[i]);
        cluster.y.push_back(unusable.y[i]);
        cluster.z.push_back(unusable.z[i]);
    }
    const std::vector<OrientationMode> mixed = cluster.Modes();
    ASSERT_EQ(mixed.size(), 1U);
    ASSERT_EQ(clean.size(), 1U);
    EXPECT_EQ(mixed[0].count, clean[0].count);
    EXPECT_EQ(mixed[0].line, clean[0].line);
}

TEST(OrientationModes, RejectsBadArguments) {
    const std::vector<float> one = {1.0f};
    const std::vector<float> two = {1.0f, 0.0f};
    EXPECT_THROW(FindOrientationModes(one, two, one, kWindowRad), Error);
    EXPECT_THROW(FindOrientationModes(one, one, one, 0.0), ConfigError);
    EXPECT_THROW(FindOrientationModes(one, one, one, 2.0), ConfigError);
    EXPECT_THROW(FindOrientationModes(one, one, one, std::numbers::pi / 2), ConfigError);
    EXPECT_NO_THROW(FindOrientationModes(one, one, one, std::numbers::pi / 4));
    EXPECT_THROW(FindOrientationModes(one, one, one, std::numeric_limits<double>::quiet_NaN()),
                 ConfigError);
}

}  // namespace
}  // namespace lidarloop::core

#include <random>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/projection.hpp"

namespace lidarloop::core {
namespace {

// A ground plane with normal `normal` through (0, 0, -1.7), sampled with noise, plus a wall and a
// pole so that the scan is not just the plane.
PointCloud TiltedGroundScan(const Eigen::Vector3f& normal, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uniform(-25.0f, 25.0f);
    std::normal_distribution<float> noise(0.0f, 0.03f);
    const Eigen::Vector3f u = normal.unitOrthogonal();
    const Eigen::Vector3f v = normal.cross(u);
    const Eigen::Vector3f origin(0.0f, 0.0f, -1.7f);
    PointCloud cloud;
    for (int i = 0; i < 30000; ++i) {
        const float along_u = uniform(rng);
        const float along_v = uniform(rng);
        cloud.push_back(origin + along_u * u + along_v * v + noise(rng) * normal);
    }
    for (int i = 0; i < 1500; ++i) {
        const float along_v = uniform(rng);
        cloud.push_back(origin + 8.0f * u + along_v * v + (std::abs(uniform(rng)) / 8) * normal);
        cloud.push_back(origin - 5.0f * v + (std::abs(uniform(rng)) / 5) * normal);
    }
    return cloud;
}

TEST(Projection, PcaRecoversTiltedGroundNormal) {
    for (const Eigen::Vector3f& normal : {Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(0.1f, 0, 1),
                                          Eigen::Vector3f(-0.2f, 0.15f, 1)}) {
        const Eigen::Vector3d truth = normal.normalized().cast<double>();
        const Eigen::Vector3d up = EstimateUpVectorPca(TiltedGroundScan(normal.normalized(), 3));
        EXPECT_GT(up.dot(truth), std::cos(0.5 * M_PI / 180.0)) << up.transpose();
        EXPECT_NEAR(up.norm(), 1.0, 1e-12);
    }
}

TEST(Projection, PcaUpVectorPointsUpEvenForUpsideDownInput) {
    PointCloud cloud = TiltedGroundScan(Eigen::Vector3f(0, 0, 1), 4);
    for (auto& p : cloud) p = -p;  // any sign the solver returns must be flipped to z >= 0
    EXPECT_GT(EstimateUpVectorPca(cloud).z(), 0.99);
}

TEST(Projection, PcaNeedsThreeFinitePoints) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(EstimateUpVectorPca(PointCloud{}), EmptyInputError);
    EXPECT_THROW(EstimateUpVectorPca({{1, 2, 3}, {4, 5, 6}, {nan, 0, 0}}), EmptyInputError);
}

// Points that span no plane have no direction of least spread: any "up" would be a guess that
// puts the histogram's heights anywhere.
TEST(Projection, PcaOfPointsSpanningNoPlaneIsAnError) {
    const PointCloud same(10, Eigen::Vector3f(1, 2, 3));  // no spread at all
    EXPECT_THROW(EstimateUpVectorPca(same), EmptyInputError);
    EXPECT_THROW(EstimateUpVectorPca(PointCloud(10, Eigen::Vector3f::Zero())), EmptyInputError);
    PointCloud line;
    for (float t = 0.0f; t < 10.0f; t += 1.0f) line.emplace_back(0.5f * t, 1.0f + 0.25f * t, 2.0f);
    EXPECT_THROW(EstimateUpVectorPca(line), EmptyInputError);
    PointCloud triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};  // three points do span a plane
    EXPECT_NEAR(EstimateUpVectorPca(triangle).z(), 1.0, 1e-12);
    // A plane of points with one far outlier: its spread outweighs the plane's, and the error
    // says that may be why.
    PointCloud outlier;
    for (int i = 0; i < 100; ++i) outlier.emplace_back(float(i % 10), float(i / 10), 0.0f);
    outlier.emplace_back(3e18f, 0.0f, 0.0f);
    try {
        EstimateUpVectorPca(outlier);
        ADD_FAILURE() << "no error";
    } catch (const EmptyInputError& e) {
        EXPECT_NE(std::string(e.what()).find("a point far from the rest"), std::string::npos)
            << e.what();
    }
}

TEST(Projection, NamesRoundTripAndUnknownNamesAreErrors) {
    EXPECT_EQ(ParseProjection(ToString(Projection::kHeight)), Projection::kHeight);
    EXPECT_EQ(ParseProjection(ToString(Projection::kRange)), Projection::kRange);
    EXPECT_EQ(ParseUpVectorMode(ToString(UpVectorMode::kPca)), UpVectorMode::kPca);
    EXPECT_EQ(ParseUpVectorMode(ToString(UpVectorMode::kFixed)), UpVectorMode::kFixed);
    EXPECT_THROW(ParseProjection("heigth"), ConfigError);
    EXPECT_THROW(ParseUpVectorMode(""), ConfigError);
}

}  // namespace
}  // namespace lidarloop::core

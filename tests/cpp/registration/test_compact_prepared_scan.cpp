// CompactPreparedScan against the PreparedScan it encodes: points within half a step, normals
// within 1e-3 rad, the same flags and counts, and the same verification verdicts.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/verification.hpp"
#include "registration_test_utils.hpp"

namespace lidarloop::registration {
namespace {

TEST(CompactPreparedScan, NormalsSurviveTheOctahedralEncodingInEveryOctant) {
    std::mt19937_64 rng(3);
    std::normal_distribution<float> gauss;
    double worst_rad = 0.0;
    for (int i = 0; i < 20000; ++i) {
        const Eigen::Vector3f normal =
            Eigen::Vector3f{gauss(rng), gauss(rng), gauss(rng)}.normalized();
        std::int16_t u = 0, v = 0;
        EncodeNormal(normal, u, v);
        const Eigen::Vector3f decoded = DecodeNormal(u, v);
        EXPECT_NEAR(decoded.norm(), 1.0F, 1e-5F);
        worst_rad =
            std::max(worst_rad, std::acos(std::clamp<double>(decoded.dot(normal), -1.0, 1.0)));
    }
    const std::vector<Eigen::Vector3f> axes = {Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, -1, 0),
                                               Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(0, 0, -1)};
    for (const Eigen::Vector3f& axis : axes) {
        std::int16_t u = 0, v = 0;
        EncodeNormal(axis, u, v);
        EXPECT_LT((DecodeNormal(u, v) - axis).norm(), 1e-4F) << axis.transpose();
    }
    EXPECT_LT(worst_rad, 1e-3);
}

TEST(CompactPreparedScan, ExpandsToThePreparedScanWithinTheQuantum) {
    const PreparedScan scan = PrepareScan(test::SyntheticPlace(), ScanReductionConfig{});
    ASSERT_GT(scan.structure->size(), 100u);
    const CompactPreparedScan compact(scan);
    const PreparedScan expanded = compact.Expand();
    ASSERT_TRUE(compact.prepared());
    EXPECT_EQ(expanded.input_points, scan.input_points);
    EXPECT_EQ(expanded.usable_points, scan.usable_points);
    EXPECT_EQ(expanded.structure_roughness_m, scan.structure_roughness_m);
    EXPECT_EQ(expanded.structure_distinctive, scan.structure_distinctive);
    EXPECT_EQ(compact.view_centre(), scan.view_centre);
    EXPECT_EQ(expanded.view_centre, scan.view_centre);
    for (const auto& [original, decoded] :
         {std::pair{scan.structure.get(), expanded.structure.get()},
          std::pair{scan.ground.get(), expanded.ground.get()}}) {
        ASSERT_EQ(decoded->size(), original->size());
        float farthest_m = 0.0F;
        for (const auto& p : original->points())
            farthest_m = std::max(farthest_m, p.cwiseAbs().maxCoeff());
        const float half_step_m = 0.5F * farthest_m / 32767.0F;
        for (std::size_t i = 0; i < original->size(); ++i) {
            EXPECT_LE((decoded->points()[i] - original->points()[i]).cwiseAbs().maxCoeff(),
                      half_step_m + 1e-5F);  // plus float rounding
            EXPECT_GT(decoded->normals()[i].dot(original->normals()[i]), 0.999999F);
        }
    }
}

TEST(CompactPreparedScan, HoldsAtMostFortyKilobytesForAFullScan) {
    const PreparedScan scan = PrepareScan(test::SyntheticPlace(), ScanReductionConfig{});
    const CompactPreparedScan compact(scan);
    const std::size_t points = scan.structure->size() + scan.ground->size();
    const std::size_t layout = LayoutSignature::kRadii * LayoutSignature::kAngles * sizeof(float);
    EXPECT_LE(compact.MemoryBytes(), 10 * points + scan.structure->size() / 8 + 64 + layout);
    EXPECT_LT(compact.MemoryBytes(), scan.MemoryBytes() / 3);
    // The caps' worst case: 3000 structure and 600 ground points.
    EXPECT_LE(10 * (3000 + 600) + 3000 / 8 + 64 + layout, 40000U);
}

TEST(CompactPreparedScan, AnEmptyScanStaysEmpty) {
    const CompactPreparedScan compact{PreparedScan{}};
    EXPECT_FALSE(compact.prepared());
    const PreparedScan expanded = compact.Expand();
    EXPECT_FALSE(expanded.structure);
    EXPECT_FALSE(expanded.ground);
    EXPECT_TRUE(compact.view_centre().hasNaN());
    EXPECT_FALSE(CompactPreparedScan{}.Expand().structure);
}

TEST(CompactPreparedScan, VerificationGivesTheSameVerdictsAndPosesOnTheExpandedScans) {
    const VerificationConfig config;
    const core::PointCloud place = test::SyntheticPlace();
    const core::Transform T_moved = test::PlanarTransform(1.5, -0.8, 0.3);
    const PreparedScan query = PrepareScan(place, config.reduction);
    const PreparedScan revisit = PrepareScan(test::Transformed(place, T_moved), config.reduction);
    const CoarseQuery coarse(*query.structure, config.coarse);
    const Verification full = Verify(query, coarse, revisit, config);
    const Verification compact =
        Verify(query, coarse, CompactPreparedScan(revisit).Expand(), config);
    ASSERT_TRUE(full.accepted);
    EXPECT_EQ(compact.accepted, full.accepted);
    EXPECT_EQ(compact.reason, full.reason);
    EXPECT_LT((compact.T_match_query.translation() - full.T_match_query.translation()).norm(),
              0.005);
    EXPECT_NEAR(compact.overlap.Min(), full.overlap.Min(), 0.01);
}

}  // namespace
}  // namespace lidarloop::registration

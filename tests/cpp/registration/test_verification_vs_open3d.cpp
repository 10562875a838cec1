// lidarloop's verification (registration::VerifyPair, default config) judged by the Open3D oracle
// (FPFH + RANSAC + GICP, tests/cpp/registration/open3d_oracle.hpp) on the same pairs: real KITTI
// scans (../shared/data/kitti-samples, never copied into the repository; skipped when absent) and
// simulated scans with exact ground truth. Where both register a true pair, their poses must
// agree; lidarloop must reject every pair of different places. Each compared pair prints its pose
// difference ("lidarloop vs Open3D").
//
// Tolerances, from verify_vs_open3d on these pairs (docs/BENCHMARK.md, 2026-11-24): lidarloop and
// Open3D differ by at most 0.016 m and 0.12 degrees on the real HDL-64E pairs and by at most
// 0.06 m and 0.65 degrees on the simulated ones (VLP-16: Open3D's pose is up to 0.53 degrees off
// the truth in roll and pitch). Real pairs: 0.05 m and 0.3 degrees; simulated: 0.1 m and 1 degree
// (the pose target is 0.35 m and 1 degree). Against exact ground truth lidarloop is within
// 0.017 m and 0.15 degrees (VLP-16 in the mine): 0.05 m and 0.3 degrees.
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <ostream>
#include <string>
#include <vector>

#include "lidarloop/registration/verification.hpp"
#include "lidarloop/sim/simulator.hpp"
#include "registration/comparison_pairs.hpp"
#include "registration/open3d_oracle.hpp"

namespace lidarloop::test {
namespace {

using registration::Verification;

const std::filesystem::path kSamplesDir = LIDARLOOP_KITTI_SAMPLES_DIR;

struct Tolerance {
    double translation_m;
    double rotation_deg;
};

constexpr Tolerance kRealAgreement{0.05, 0.3};
constexpr Tolerance kSimulatedAgreement{0.1, 1.0};
constexpr Tolerance kSimulatedTruth{0.05, 0.3};

bool Within(const PoseDifference& d, Tolerance tolerance) {
    return d.translation_m < tolerance.translation_m && d.rotation_deg < tolerance.rotation_deg;
}

void ExpectAgree(const core::Transform& lidarloop, const core::Transform& open3d,
                 Tolerance tolerance) {
    const PoseDifference d = Difference(lidarloop, open3d);
    EXPECT_TRUE(Within(d, tolerance))
        << "lidarloop vs Open3D: " << d.translation_m << " m, " << d.rotation_deg
        << " deg; tolerance " << tolerance.translation_m << " m, " << tolerance.rotation_deg
        << " deg\nlidarloop\n"
        << lidarloop.matrix() << "\nOpen3D\n"
        << open3d.matrix();
}

// The comparison catches a lidarloop pose moved by twice the tolerance along x, or turned by
// twice it about z: the check that this test can fail at all.
void ExpectPerturbedPoseFails(const core::Transform& lidarloop, const core::Transform& open3d,
                              Tolerance tolerance) {
    core::Transform shifted = lidarloop;
    shifted.translation().x() += 2.0 * tolerance.translation_m;
    EXPECT_NONFATAL_FAILURE(ExpectAgree(shifted, open3d, tolerance), "lidarloop vs Open3D");
    const core::Transform turned =
        lidarloop * Eigen::AngleAxisd(2.0 * tolerance.rotation_deg * std::numbers::pi / 180.0,
                                      Eigen::Vector3d::UnitZ());
    EXPECT_NONFATAL_FAILURE(ExpectAgree(turned, open3d, tolerance), "lidarloop vs Open3D");
}

void Report(const ScanPair& pair, const Verification& mine, const Open3dRegistration* theirs) {
    const PoseDifference truth = Difference(mine.T_match_query, pair.T_match_query_truth);
    std::printf("[ pair     ] %s (%s): lidarloop %s (%s), vs truth %.3f m %.2f deg",
                pair.name.c_str(), ToString(pair.kind), mine.accepted ? "accepts" : "rejects",
                registration::ToString(mine.reason).c_str(), truth.translation_m,
                truth.rotation_deg);
    if (theirs != nullptr) {
        const PoseDifference d = Difference(mine.T_match_query, theirs->T_match_query);
        const PoseDifference o = Difference(theirs->T_match_query, pair.T_match_query_truth);
        std::printf(
            "; Open3D fitness %.3f, vs truth %.3f m %.2f deg; lidarloop vs Open3D %.3f m "
            "%.2f deg",
            theirs->fitness, o.translation_m, o.rotation_deg, d.translation_m, d.rotation_deg);
    }
    std::printf("\n");
}

// Did the oracle find the pose? KITTI's loops drift between visits (samples README.md: judge
// the yaw within 2 degrees and the planar translation within 1.5 m); elsewhere the truth is exact.
bool OracleAligned(const ScanPair& pair, const Open3dRegistration& theirs, Tolerance exact) {
    const PoseDifference d = Difference(theirs.T_match_query, pair.T_match_query_truth);
    if (!pair.exact_truth) return std::abs(d.yaw_deg) < 2.0 && d.planar_m < 1.5;
    return Within(d, exact);
}

TEST(VerificationVsOpen3d, RealKittiPairs) {
    const std::vector<ScanPair> pairs = KittiPairs(kSamplesDir);
    if (pairs.empty()) {
        GTEST_SKIP() << "KITTI samples not found at " << kSamplesDir.lexically_normal()
                     << ": KITTI's licence keeps real scans out of the repository; put the "
                        "samples there to run this test";
    }
    for (const ScanPair& pair : pairs) {
        SCOPED_TRACE(pair.name);
        const Verification mine = registration::VerifyPair(pair.query, pair.match, {});
        if (pair.kind == PairKind::kDifferentPlace) {
            // No truth to judge an alignment by, and Open3D spends 2-3.5 s on it: not run.
            Report(pair, mine, nullptr);
            EXPECT_FALSE(mine.accepted);
            continue;
        }
        const Open3dRegistration theirs = RegisterWithOpen3d(pair.query, pair.match);
        Report(pair, mine, &theirs);
        // The consecutive pairs' truth holds to centimetres (as test_open3d_oracle checks).
        ASSERT_TRUE(OracleAligned(pair, theirs, {0.05, 0.2})) << "the oracle failed";
        EXPECT_TRUE(mine.accepted) << registration::ToString(mine.reason);
        ExpectAgree(mine.T_match_query, theirs.T_match_query, kRealAgreement);
        ExpectPerturbedPoseFails(mine.T_match_query, theirs.T_match_query, kRealAgreement);
    }
}

struct Drive {
    sim::SceneType scene;
    sim::SensorModel sensor;
};

// GoogleTest's name of a parameter (else it prints the struct's bytes).
void PrintTo(const Drive& drive, std::ostream* out) {
    *out << sim::ToString(drive.scene) << " " << sim::ToString(drive.sensor);
}

class SimulatedVsOpen3d : public ::testing::TestWithParam<Drive> {};

// A revisit in the opposite direction a lane to the side, one in the same direction a lane to
// the side, and the opposite-direction query against the drive's farthest scan: 119 m away
// (urban) but only 27 m in the mine, whose pillars repeat every 20 m. There lidarloop's best
// pose (and Open3D's) is an alias 20 m from the truth, with the right yaw, and the RMSE test
// rejects it. The revisits must also be within 0.1 m and 1 degree of the truth for Open3D.
TEST_P(SimulatedVsOpen3d, SimulatedPairs) {
    const Drive drive = GetParam();
    const sim::Simulator simulator(UTurnDrive(drive.scene, drive.sensor));
    const std::vector<ScanPair> pairs =
        SimulatedPairs(simulator, sim::ToString(drive.scene) + " " + sim::ToString(drive.sensor));
    ASSERT_EQ(pairs.size(), 3u) << "the drive lacks a revisit";
    int compared = 0;
    for (const ScanPair& pair : pairs) {
        SCOPED_TRACE(pair.name);
        const Verification mine = registration::VerifyPair(pair.query, pair.match, {});
        if (pair.kind == PairKind::kDifferentPlace) {
            Report(pair, mine, nullptr);
            EXPECT_FALSE(mine.accepted);
            continue;
        }
        EXPECT_TRUE(mine.accepted) << registration::ToString(mine.reason);
        EXPECT_TRUE(
            Within(Difference(mine.T_match_query, pair.T_match_query_truth), kSimulatedTruth));
        const Open3dRegistration theirs = RegisterWithOpen3d(pair.query, pair.match);
        Report(pair, mine, &theirs);
        // Where the oracle misses the truth it judges nothing (none of these pairs; it does on
        // rural VLP-16 scans, docs/BENCHMARK.md): lidarloop has been held to the truth above.
        if (!OracleAligned(pair, theirs, kSimulatedAgreement)) continue;
        ++compared;
        ExpectAgree(mine.T_match_query, theirs.T_match_query, kSimulatedAgreement);
        ExpectPerturbedPoseFails(mine.T_match_query, theirs.T_match_query, kSimulatedAgreement);
    }
    EXPECT_EQ(compared, 2) << "the oracle aligned only " << compared << " of the 2 revisits";
}

INSTANTIATE_TEST_SUITE_P(Drives, SimulatedVsOpen3d,
                         ::testing::Values(Drive{sim::SceneType::kUrban, sim::SensorModel::kHdl64},
                                           Drive{sim::SceneType::kUrban, sim::SensorModel::kVlp16},
                                           Drive{sim::SceneType::kMine, sim::SensorModel::kHdl64},
                                           Drive{sim::SceneType::kMine, sim::SensorModel::kVlp16}),
                         [](const ::testing::TestParamInfo<Drive>& param_info) {
                             return sim::ToString(param_info.param.scene) + "_" +
                                    sim::ToString(param_info.param.sensor);
                         });

}  // namespace
}  // namespace lidarloop::test

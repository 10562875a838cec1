#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/trajectory.hpp"
#include "lidarloop/posegraph/optimiser.hpp"
#include "posegraph/posegraph_test_utils.hpp"

namespace lidarloop::posegraph {
namespace {

using test::DriftingOdometry;
using test::EllipseLaps;
using test::PlanarPose;
using test::TrueLoops;
using test::WrongLoops;

double MaxPositionError(const std::vector<core::Transform>& a,
                        const std::vector<core::Transform>& b) {
    double error = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        error = std::max(error, (a[i].translation() - b[i].translation()).norm());
    }
    return error;
}

OptimisationResult OptimiseLoops(const std::vector<core::Transform>& odometry,
                                 const std::vector<LoopConstraint>& loops,
                                 const PoseGraphConfig& config = {}) {
    return Optimise(BuildPoseGraph(odometry, loops, config), config);
}

TEST(EdgeError, ZeroWhenTheEstimatesAgreeAndG2oConventionOtherwise) {
    const core::Transform a = PlanarPose(1, 2, 0.3, 0.5);
    const core::Transform b = PlanarPose(4, -1, -1.2, 0.7);
    EXPECT_LT(EdgeError(a.inverse() * b, a, b).norm(), 1e-12);
    // Moving `to` by 1 m along its own x axis: translation error (1, 0, 0) in its frame.
    core::Transform moved = b;
    moved.translate(Eigen::Vector3d(1, 0, 0));
    const Vector6d e = EdgeError(a.inverse() * b, a, moved);
    EXPECT_NEAR(e[0], 1.0, 1e-12);
    EXPECT_NEAR(e.segment<2>(1).norm() + e.tail<3>().norm(), 0.0, 1e-12);
    // Turning `to` by 0.2 rad about its z: quaternion vector (0, 0, sin(0.1)).
    core::Transform turned = b;
    turned.rotate(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()));
    const Vector6d r = EdgeError(a.inverse() * b, a, turned);
    EXPECT_NEAR(r[5], std::sin(0.1), 1e-12);
    EXPECT_NEAR(r.head<5>().norm(), 0.0, 1e-12);
}

TEST(Information, OdometryGrowsWithTheStepAndLoopsWithQuality) {
    const InformationConfig config;
    const Matrix6d short_step = OdometryInformation(PlanarPose(0.5, 0, 0), config);
    const Matrix6d long_step = OdometryInformation(PlanarPose(5, 0, 0), config);
    EXPECT_GT(short_step(0, 0), long_step(0, 0));
    EXPECT_GT(short_step(5, 5), long_step(5, 5));
    // 1 m and 0.3 deg of drift per 100 m: sigma^2 = min^2 + a^2 * l.
    const double sigma_t = std::sqrt(0.01 * 0.01 + 0.01 * 5);
    EXPECT_NEAR(long_step(0, 0), 1.0 / (sigma_t * sigma_t), 1e-9);
    LoopConstraint good;
    good.overlap = 0.8;
    good.rmse_m = 0.05;
    LoopConstraint poor = good;
    poor.overlap = 0.2;
    poor.rmse_m = 0.3;
    EXPECT_GT(LoopInformation(good, config)(0, 0), LoopInformation(poor, config)(0, 0));
    EXPECT_GT(LoopInformation(good, config)(3, 3), LoopInformation(poor, config)(3, 3));
}

// Some frames of a long drive: three poses 3 m apart in a line, 600 m of path between the last
// two. The odometry's drift, its information and the gate's tolerance grow with that path, not
// with the straight step.
TEST(Optimise, ThePathTravelledBetweenFramesSetsTheOdometrysDrift) {
    const std::vector<core::Transform> frames = {PlanarPose(0, 0, 0), PlanarPose(3, 0, 0),
                                                 PlanarPose(6, 0, 0)};
    const std::vector<double> path_m = {0.0, 3.0, 603.0};
    const InformationConfig information;
    EXPECT_NEAR(OdometryInformation(frames[1].inverse() * frames[2], information, 600.0)(0, 0),
                OdometryInformation(PlanarPose(600, 0, 0), information)(0, 0), 1e-12);
    const PoseGraph graph = BuildPoseGraph(frames, {}, {}, path_m);
    ASSERT_EQ(graph.edges.size(), 2u);
    EXPECT_NEAR(graph.edges[1].information(0, 0),
                OdometryInformation(PlanarPose(600, 0, 0), information)(0, 0), 1e-12);
    EXPECT_NEAR(graph.edges[0].information(0, 0),
                OdometryInformation(PlanarPose(3, 0, 0), information)(0, 0), 1e-12);
    // A loop 6 m off the odometry between scans 600 m of path apart: within the drift of 600 m
    // (the gate allows about 5 sigma + 3 m + 3 %), far beyond that of the 3 m line.
    const LoopConstraint loop{2, 1, PlanarPose(-3, 0, 0)};
    const OptimisationResult along_path = Optimise(BuildPoseGraph(frames, {loop}, {}, path_m), {});
    ASSERT_EQ(along_path.loops.size(), 1u);
    EXPECT_EQ(along_path.loops[0].verdict, LoopVerdict::kUsed);
    EXPECT_NEAR(along_path.loops[0].path_m, 600.0, 1e-9);
    const OptimisationResult straight = Optimise(BuildPoseGraph(frames, {loop}, {}), {});
    EXPECT_EQ(straight.loops[0].verdict, LoopVerdict::kRejectedByOdometry);
    EXPECT_THROW(BuildPoseGraph(frames, {}, {}, {0.0, 3.0}), core::ConfigError);
    EXPECT_THROW(BuildPoseGraph(frames, {}, {}, {0.0, 603.0, 3.0}), core::ConfigError);
    EXPECT_THROW(BuildPoseGraph(frames, {}, {}, {0.0, std::nan(""), 603.0}), core::ConfigError);
}

TEST(Optimise, NoiseFreeGraphStaysAtTheTruth) {
    const std::vector<core::Transform> truth = EllipseLaps(2);
    const auto result = OptimiseLoops(truth, TrueLoops(truth, 1, 5, 50, 5.0, 0.0, 0.0));
    ASSERT_GT(result.loops_used, 10u);
    EXPECT_EQ(result.rejected_by_odometry + result.rejected_by_residual, 0u);
    EXPECT_LT(MaxPositionError(result.poses, truth), 1e-6);
    EXPECT_NEAR(result.final_cost, 0.0, 1e-9);
}

TEST(Optimise, OneLoopRemovesAKnownInjectedDrift) {
    // A square driven once with a constant yaw error of 0.1 degree per 2 m step (100 steps):
    // the odometry misses the start by metres; one exact loop from the last pose to the first
    // brings every pose back near the truth. The information model is told of the larger drift.
    std::vector<core::Transform> truth;
    for (int side = 0; side < 4; ++side) {
        for (int k = 0; k < 25; ++k) {
            const double yaw = side * std::numbers::pi / 2;
            const Eigen::Vector2d corner = side == 0   ? Eigen::Vector2d(0, 0)
                                           : side == 1 ? Eigen::Vector2d(50, 0)
                                           : side == 2 ? Eigen::Vector2d(50, 50)
                                                       : Eigen::Vector2d(0, 50);
            truth.push_back(PlanarPose(corner.x() + 2.0 * k * std::cos(yaw),
                                       corner.y() + 2.0 * k * std::sin(yaw), yaw));
        }
    }
    truth.push_back(PlanarPose(0, 0, 0));  // back at the start
    std::vector<core::Transform> odometry = {truth.front()};
    for (std::size_t i = 1; i < truth.size(); ++i) {
        core::Transform step = truth[i - 1].inverse() * truth[i];
        step.rotate(Eigen::AngleAxisd(0.1 * std::numbers::pi / 180, Eigen::Vector3d::UnitZ()));
        odometry.push_back(odometry.back() * step);
    }
    const LoopConstraint loop{truth.size() - 1, 0, truth.front().inverse() * truth.back()};
    PoseGraphConfig config;
    config.information.odometry_rotation_sigma_deg_per_sqrt_m = 0.5;
    const auto result = OptimiseLoops(odometry, {loop}, config);
    ASSERT_EQ(result.loops_used, 1u)
        << ToString(result.loops[0].verdict) << " residual " << result.loops[0].whitened_residual
        << " odometry error " << result.loops[0].odometry_translation_error_m << " m "
        << result.loops[0].odometry_rotation_error_deg << " deg, gate "
        << result.loops[0].gate_translation_m << " m " << result.loops[0].gate_rotation_deg;
    const double before = eval::AbsoluteTrajectoryRmse(odometry, truth);
    const double after = eval::AbsoluteTrajectoryRmse(result.poses, truth);
    EXPECT_GT(before, 1.0);
    EXPECT_LT(after, before / 5.0);
    // The loop itself is closed.
    EXPECT_LT((result.poses.back().translation() - result.poses.front().translation()).norm(), 0.5);
}

TEST(Optimise, LoopsShrinkTheDriftOfSeveralLaps) {
    const std::vector<core::Transform> truth = EllipseLaps(3);
    const std::vector<core::Transform> odometry = DriftingOdometry(truth, 7);
    const auto result = OptimiseLoops(odometry, TrueLoops(truth, 3));
    const double before = eval::AbsoluteTrajectoryRmse(odometry, truth);
    const double after = eval::AbsoluteTrajectoryRmse(result.poses, truth);
    EXPECT_GT(before, 2.0);
    EXPECT_LT(after, before / 5.0) << "before " << before << " after " << after;
    EXPECT_EQ(result.rejected_by_odometry + result.rejected_by_residual, 0u);
    EXPECT_TRUE(result.converged);
}

struct WrongLoopCase {
    std::vector<core::Transform> truth;
    std::vector<core::Transform> odometry;
    std::vector<LoopConstraint> good;
    double clean_ate = 0.0;

    WrongLoopCase() : truth(EllipseLaps(3)), odometry(DriftingOdometry(truth, 11)) {
        good = TrueLoops(truth, 5);
        clean_ate = eval::AbsoluteTrajectoryRmse(OptimiseLoops(odometry, good).poses, truth);
    }
};

TEST(Optimise, TenPercentWrongLoopsBarelyMatter) {
    const WrongLoopCase c;
    for (const std::uint64_t seed : {1u, 2u, 3u}) {
        std::vector<LoopConstraint> loops = c.good;
        const auto wrong = WrongLoops(c.truth.size(), (c.good.size() + 9) / 10, seed);
        loops.insert(loops.end(), wrong.begin(), wrong.end());
        const auto result = OptimiseLoops(c.odometry, loops);
        const double ate = eval::AbsoluteTrajectoryRmse(result.poses, c.truth);
        EXPECT_LT(ate, 1.5 * c.clean_ate) << "seed " << seed << ", clean " << c.clean_ate;
        // Every wrong loop is rejected by one of the checks.
        for (const LoopResult& loop : result.loops) {
            if (loop.loop >= c.good.size()) {
                EXPECT_NE(loop.verdict, LoopVerdict::kUsed) << "wrong loop " << loop.loop;
            }
        }
    }
}

TEST(Optimise, OneWrongLoopChangesTheResultByLessThanTenPercent) {
    const WrongLoopCase c;
    for (const std::uint64_t seed : {4u, 5u, 6u}) {
        std::vector<LoopConstraint> loops = c.good;
        loops.push_back(WrongLoops(c.truth.size(), 1, seed).front());
        const auto result = OptimiseLoops(c.odometry, loops);
        const double ate = eval::AbsoluteTrajectoryRmse(result.poses, c.truth);
        EXPECT_LT(ate, 1.1 * c.clean_ate) << "seed " << seed << ", clean " << c.clean_ate;
        EXPECT_NE(result.loops.back().verdict, LoopVerdict::kUsed);
    }
}

TEST(Optimise, GateRejectsALoopTheOdometryCannotExplain) {
    const std::vector<core::Transform> truth = EllipseLaps(1);
    LoopConstraint upside_down{100, 10, PlanarPose(0, 0, 0)};
    upside_down.T_match_query = truth[10].inverse() * truth[100];
    upside_down.T_match_query.rotate(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
    const auto result = OptimiseLoops(truth, {upside_down});
    ASSERT_EQ(result.loops.size(), 1u);
    EXPECT_EQ(result.loops[0].verdict, LoopVerdict::kRejectedByOdometry);
    EXPECT_NEAR(result.loops[0].odometry_rotation_error_deg, 180.0, 1e-6);
    EXPECT_FALSE(result.note.empty());
    EXPECT_LT(MaxPositionError(result.poses, truth), 1e-12);
}

// The tolerance at the defaults over d = 100 m: 5 sigma_t + 3 m + 3 % of d, with
// sigma_t^2 = 0.1^2 d + (0.03 deg in rad)^2 d^3 / 3; and 5 * 0.03 * sqrt(d) + 10 + 1 deg.
TEST(GateAgainstOdometry, ToleranceGrowsWithThePathAsTheInformationModelSays) {
    const double d = 100.0;
    const double a_r = 0.03 * std::numbers::pi / 180.0;
    const double sigma_t = std::sqrt(0.01 * d + a_r * a_r * d * d * d / 3.0);
    const double tolerance_m = 5.0 * sigma_t + 3.0 + 0.03 * d;
    const core::Transform T_odometry = PlanarPose(30.0, -4.0, 0.3);
    const auto shifted_by = [&](double x_m) {
        return GateAgainstOdometry(T_odometry * PlanarPose(x_m, 0.0, 0.0), T_odometry, d, {});
    };
    const LoopResult inside = shifted_by(tolerance_m - 0.01);
    EXPECT_EQ(inside.verdict, LoopVerdict::kUsed);
    EXPECT_NEAR(inside.gate_translation_m, tolerance_m, 1e-9);
    EXPECT_NEAR(inside.odometry_translation_error_m, tolerance_m - 0.01, 1e-9);
    EXPECT_NEAR(inside.gate_rotation_deg, 5.0 * 0.03 * 10.0 + 10.0 + 1.0, 1e-9);
    EXPECT_EQ(GateTranslationM(d, {}), inside.gate_translation_m);
    EXPECT_EQ(GateRotationDeg(d, {}), inside.gate_rotation_deg);
    EXPECT_EQ(inside.path_m, d);
    EXPECT_EQ(shifted_by(tolerance_m + 0.01).verdict, LoopVerdict::kRejectedByOdometry);
    // A street that repeats itself every 45 m: registered a period off, 54 m of path apart.
    EXPECT_EQ(
        GateAgainstOdometry(T_odometry * PlanarPose(45.0, 0.0, 0.0), T_odometry, 54.0, {}).verdict,
        LoopVerdict::kRejectedByOdometry);
    const LoopResult turned =
        GateAgainstOdometry(T_odometry * PlanarPose(0.0, 0.0, 0.25), T_odometry, d, {});
    EXPECT_NEAR(turned.odometry_rotation_error_deg, 0.25 * 180.0 / std::numbers::pi, 1e-9);
    EXPECT_EQ(turned.verdict, LoopVerdict::kRejectedByOdometry);  // 14.3 deg > 12.5 deg
}

TEST(Optimise, WithoutLoopsTheOdometryComesBackUnchangedWithANote) {
    const std::vector<core::Transform> truth = EllipseLaps(1);
    const std::vector<core::Transform> odometry = DriftingOdometry(truth, 3);
    const auto result = OptimiseLoops(odometry, {});
    EXPECT_EQ(result.solves, 0);
    EXPECT_NE(result.note.find("no loop"), std::string::npos);
    for (std::size_t i = 0; i < odometry.size(); ++i) {
        EXPECT_TRUE(result.poses[i].isApprox(odometry[i], 0.0)) << i;
    }
}

// Odometry that freezes early in the second lap, then goes on from where it stopped: every loop
// after the freeze disagrees with it by the missing 80 m (issue 25, item 8).
TEST(SummariseRejections, NamesTheCauseWhenMostLoopsAreRejected) {
    const std::vector<core::Transform> truth = EllipseLaps(2);
    const std::size_t begin = truth.size() / 2 + 5, end = begin + 40;
    std::vector<core::Transform> odometry = {truth.front()};
    for (std::size_t i = 1; i < truth.size(); ++i) {
        const bool frozen = i > begin && i <= end;
        odometry.push_back(frozen ? odometry.back()
                                  : odometry.back() * (truth[i - 1].inverse() * truth[i]));
    }
    const PoseGraph graph = BuildPoseGraph(odometry, TrueLoops(truth, 3, 2), {});
    const OptimisationResult result = Optimise(graph, {});
    ASSERT_GT(2 * (result.loops.size() - result.loops_used), result.loops.size());
    const std::string summary = SummariseRejections(graph, result);
    EXPECT_NE(summary.find(" loops rejected, "), std::string::npos) << summary;
    EXPECT_NE(summary.find("against the odometry: does the odometry reset or freeze?"),
              std::string::npos)
        << summary;
    EXPECT_NE(summary.find("longest standstill: scans " + std::to_string(begin) + " to " +
                           std::to_string(end)),
              std::string::npos)
        << summary;
    // Good odometry: no summary.
    const PoseGraph good = BuildPoseGraph(truth, TrueLoops(truth, 3, 2), {});
    EXPECT_EQ(SummariseRejections(good, Optimise(good, {})), "");
}

TEST(SummariseRejections, NamesTheCountsWhenTheLoopsDisagreeAmongThemselves) {
    PoseGraph graph;
    graph.poses = {PlanarPose(0, 0, 0), PlanarPose(1, 0, 0), PlanarPose(31, 0, 0)};
    OptimisationResult result;
    result.loops.resize(4);
    result.loops_used = 1;
    result.rejected_by_odometry = 1;
    result.rejected_by_residual = 2;
    EXPECT_EQ(SummariseRejections(graph, result),
              "3 of 4 loops rejected, 1 against the odometry, 0 without support, 2 by their "
              "residual: are the loops of this sequence, and is the odometry right? (largest "
              "step 30.0 m, median 30.0 m, from scan 1 to 2; no standstill)");
    result.loops_used = 2;
    result.rejected_by_residual = 1;
    EXPECT_EQ(SummariseRejections(graph, result), "");  // half is not most
    result.loops.resize(2);
    result.loops_used = 0;
    EXPECT_EQ(SummariseRejections(graph, result), "");  // two wrong loops are no pattern
}

TEST(Optimise, BadInput) {
    const std::vector<core::Transform> poses = EllipseLaps(1);
    EXPECT_THROW(BuildPoseGraph(poses, {{poses.size(), 0, core::Transform::Identity()}}, {}),
                 core::ConfigError);
    EXPECT_THROW(BuildPoseGraph(poses, {{5, 5, core::Transform::Identity()}}, {}),
                 core::ConfigError);
    EXPECT_THROW(Optimise(PoseGraph{}, {}), core::ConfigError);
    // Coordinates beyond any Earth-fixed frame (a wrong loop, a corrupt file) are refused before
    // the solver, which does not come back from 1e200 m; so are non-finite edges.
    PoseGraph far = BuildPoseGraph(poses, {}, {});
    far.poses[3].translation().x() = 1e200;
    EXPECT_THROW(Optimise(far, {}), core::ConfigError);
    PoseGraph nan_edge = BuildPoseGraph(poses, {}, {});
    nan_edge.edges.front().information(0, 0) = std::nan("");
    EXPECT_THROW(Optimise(nan_edge, {}), core::ConfigError);
    EXPECT_NO_THROW(Optimise(BuildPoseGraph(poses, {}, {}), {}));
    PoseGraphConfig config;
    config.robust.cauchy_scale = 0.0;
    try {
        config.Validate();
        FAIL() << "no error";
    } catch (const core::ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("posegraph.robust.cauchy_scale"), std::string::npos)
            << e.what();
    }
    config = {};
    config.information.odometry_translation_sigma_m_per_sqrt_m = std::nan("");
    EXPECT_THROW(config.Validate(), core::ConfigError);
}

}  // namespace
}  // namespace lidarloop::posegraph

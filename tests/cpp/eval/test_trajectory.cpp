#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/trajectory.hpp"
#include "test_utils.hpp"

namespace lidarloop::eval {
namespace {

using test::kDeg;

core::Transform Pose(double x, double y, double z, double yaw, double pitch = 0.0) {
    core::Transform T = core::Transform::Identity();
    T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
                     .toRotationMatrix();
    T.translation() = Eigen::Vector3d(x, y, z);
    return T;
}

// A wiggly 3-D path, a pose per metre or so.
std::vector<core::Transform> Wiggle(std::size_t n) {
    std::vector<core::Transform> poses;
    for (std::size_t i = 0; i < n; ++i) {
        const double s = static_cast<double>(i);
        poses.push_back(Pose(s, 20.0 * std::sin(s / 40.0), 3.0 * std::sin(s / 25.0),
                             std::atan(0.5 * std::cos(s / 40.0))));
    }
    return poses;
}

std::vector<core::Transform> Moved(const std::vector<core::Transform>& poses,
                                   const core::Transform& T) {
    std::vector<core::Transform> moved;
    for (const auto& pose : poses) moved.push_back(T * pose);
    return moved;
}

TEST(AbsoluteTrajectoryRmse, ZeroForARigidlyMovedCopy) {
    const auto truth = Wiggle(300);
    const auto estimate = Moved(truth, Pose(100, -40, 7, 2.0, 0.3));
    EXPECT_LT(AbsoluteTrajectoryRmse(estimate, truth), 1e-9);
}

TEST(AbsoluteTrajectoryRmse, KnownAnswerForSymmetricOffsets) {
    // Points on a square with alternate points pushed +-0.5 m in z: the best alignment cannot
    // remove a zero-mean, rotation-free pattern, so the RMSE is 0.5 m.
    std::vector<core::Transform> truth, estimate;
    for (int i = 0; i < 40; ++i) {
        const double a = i * 2.0 * std::numbers::pi / 40.0;
        truth.push_back(Pose(10.0 * std::cos(a), 10.0 * std::sin(a), 0.0, 0.0));
        estimate.push_back(Pose(10.0 * std::cos(a), 10.0 * std::sin(a), i % 2 ? 0.5 : -0.5, 0.0));
    }
    EXPECT_NEAR(AbsoluteTrajectoryRmse(Moved(estimate, Pose(3, 4, 5, 1.0)), truth), 0.5, 1e-9);
}

// The alignment against a brute-force search over yaw (planar data: the best rotation is about
// z), with the translation that matches the centroids for each yaw.
TEST(AbsoluteTrajectoryRmse, MatchesABruteForceYawSearch) {
    std::mt19937_64 rng(5);
    std::normal_distribution<double> noise(0.0, 0.3);
    auto truth = Wiggle(200);
    for (auto& pose : truth) pose.translation().z() = 0.0;
    std::vector<core::Transform> estimate;
    for (const auto& pose : Moved(truth, Pose(5, 5, 0, 0.7))) {
        core::Transform p = pose;
        p.translation() += Eigen::Vector3d{noise(rng), noise(rng), 0.0};
        estimate.push_back(p);
    }
    // RMSE at one yaw, with the translation that matches the centroids.
    const auto rmse_at = [&](double yaw_deg) {
        const Eigen::Matrix3d R =
            Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
        Eigen::Vector3d mean_e = Eigen::Vector3d::Zero(), mean_t = Eigen::Vector3d::Zero();
        for (std::size_t i = 0; i < truth.size(); ++i) {
            mean_e += R * estimate[i].translation();
            mean_t += truth[i].translation();
        }
        const Eigen::Vector3d t = (mean_t - mean_e) / static_cast<double>(truth.size());
        double sum = 0.0;
        for (std::size_t i = 0; i < truth.size(); ++i) {
            sum += (truth[i].translation() - R * estimate[i].translation() - t).squaredNorm();
        }
        return std::sqrt(sum / static_cast<double>(truth.size()));
    };
    // Every degree, then every 0.001 degree around the best one.
    double best_deg = 0.0;
    for (int k = 0; k < 360; ++k) {
        if (rmse_at(k) < rmse_at(best_deg)) best_deg = k;
    }
    double best = rmse_at(best_deg);
    for (int k = -1000; k <= 1000; ++k) best = std::min(best, rmse_at(best_deg + k * 1e-3));
    const double ate = AbsoluteTrajectoryRmse(estimate, truth);
    EXPECT_LE(ate, best + 1e-9);
    EXPECT_NEAR(ate, best, 1e-6);
}

TEST(AbsoluteTrajectoryRmse, BadInput) {
    const auto truth = Wiggle(10);
    EXPECT_THROW(AbsoluteTrajectoryRmse(Wiggle(9), truth), core::ConfigError);
    EXPECT_THROW(AbsoluteTrajectoryRmse({}, {}), core::ConfigError);
}

// A straight line driven 1 % too long and turning 0.3 degrees per 100 m: KITTI RPE is exactly
// 1 % translation (the heading error adds a little) and 0.3 deg / 100 m.
TEST(TrajectoryRpe, KnownAnswerForScaleAndHeadingDrift) {
    std::vector<core::Transform> truth, scaled, turning;
    for (int i = 0; i <= 1000; ++i) {
        truth.push_back(Pose(i, 0, 0, 0));
        scaled.push_back(Pose(1.01 * i, 0, 0, 0));
        turning.push_back(Pose(i, 0, 0, 0.003 * kDeg * i));
    }
    const TrajectoryRpe s = ComputeTrajectoryRpe(scaled, truth);
    EXPECT_NEAR(s.translation_percent, 1.0, 1e-9);
    EXPECT_NEAR(s.rotation_deg_per_100m, 0.0, 1e-9);
    const TrajectoryRpe r = ComputeTrajectoryRpe(turning, truth);
    EXPECT_NEAR(r.rotation_deg_per_100m, 0.3, 1e-9);
    // Segments: from poses 0, 10, ..., 1000, every length L with first + L <= 1000.
    std::size_t expected = 0;
    for (int first = 0; first <= 1000; first += 10) {
        for (int L = 100; L <= 800; L += 100) expected += first + L <= 1000 ? 1 : 0;
    }
    EXPECT_EQ(s.segments, expected);
    EXPECT_NEAR(ComputeTrajectoryRpe(truth, truth).translation_percent, 0.0, 1e-12);
}

// Against a plain re-computation from its definition on a curved, noisy path.
TEST(TrajectoryRpe, MatchesAPlainReference) {
    const auto truth = Wiggle(900);
    std::mt19937_64 rng(9);
    std::normal_distribution<double> noise(0.0, 0.01);
    std::vector<core::Transform> estimate = {truth.front()};
    for (std::size_t i = 1; i < truth.size(); ++i) {
        core::Transform step = truth[i - 1].inverse() * truth[i];
        step.translation() *= 1.0 + noise(rng);
        step.rotate(Eigen::AngleAxisd(noise(rng), Eigen::Vector3d::UnitZ()));
        estimate.push_back(estimate.back() * step);
    }
    double t_sum = 0.0, r_sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < truth.size(); i += 10) {
        for (double L = 100; L <= 800; L += 100) {
            double d = 0.0;
            std::size_t j = i;
            while (j + 1 < truth.size() && d < L) {
                d += (truth[j + 1].translation() - truth[j].translation()).norm();
                ++j;
            }
            if (d < L) continue;
            const core::Transform E =
                (truth[i].inverse() * truth[j]).inverse() * (estimate[i].inverse() * estimate[j]);
            t_sum += E.translation().norm() / L;
            r_sum += std::acos(std::clamp((E.linear().trace() - 1.0) / 2.0, -1.0, 1.0)) / L;
            ++count;
        }
    }
    const TrajectoryRpe rpe = ComputeTrajectoryRpe(estimate, truth);
    ASSERT_EQ(rpe.segments, count);
    EXPECT_NEAR(rpe.translation_percent, 100.0 * t_sum / static_cast<double>(count), 1e-9);
    EXPECT_NEAR(rpe.rotation_deg_per_100m, 100.0 * r_sum / static_cast<double>(count) / kDeg, 1e-6);
}

TEST(TrajectoryRpe, ShortTrajectoryHasNoSegment) {
    const auto truth = Wiggle(50);
    const TrajectoryRpe rpe = ComputeTrajectoryRpe(truth, truth);
    EXPECT_EQ(rpe.segments, 0u);
    EXPECT_TRUE(std::isnan(rpe.translation_percent));
    EXPECT_THROW(ComputeTrajectoryRpe(Wiggle(49), truth), core::ConfigError);
    EXPECT_THROW(ComputeTrajectoryRpe(truth, truth, {{100.0}, 0}), core::ConfigError);
}

}  // namespace
}  // namespace lidarloop::eval

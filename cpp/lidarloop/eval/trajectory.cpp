#include "lidarloop/eval/trajectory.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <Eigen/SVD>

#include "lidarloop/core/error.hpp"

namespace lidarloop::eval {
namespace {

void RequireSameSize(std::size_t estimate, std::size_t truth) {
    if (estimate != truth) {
        throw core::ConfigError("the estimate has " + std::to_string(estimate) +
                                " poses and the ground truth " + std::to_string(truth));
    }
}

std::vector<Eigen::Vector3d> Positions(const std::vector<core::Transform>& poses) {
    std::vector<Eigen::Vector3d> positions;
    positions.reserve(poses.size());
    for (const auto& pose : poses) positions.push_back(pose.translation());
    return positions;
}

}  // namespace

core::Transform AlignRigid(const std::vector<Eigen::Vector3d>& estimate,
                           const std::vector<Eigen::Vector3d>& truth) {
    RequireSameSize(estimate.size(), truth.size());
    core::Transform T = core::Transform::Identity();
    if (estimate.empty()) return T;
    Eigen::Vector3d mean_estimate = Eigen::Vector3d::Zero();
    Eigen::Vector3d mean_truth = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < estimate.size(); ++i) {
        mean_estimate += estimate[i];
        mean_truth += truth[i];
    }
    const double n = static_cast<double>(estimate.size());
    mean_estimate /= n;
    mean_truth /= n;
    // Cross-covariance of the centred points (Umeyama eq. 38, without the 1/n).
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < estimate.size(); ++i) {
        covariance += (truth[i] - mean_truth) * (estimate[i] - mean_estimate).transpose();
    }
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                                Eigen::ComputeFullU | Eigen::ComputeFullV);
    // Umeyama eq. 39-40: flip the weakest axis when the best orthogonal map is a reflection.
    Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
    if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
    T.linear() = svd.matrixU() * S * svd.matrixV().transpose();
    T.translation() = mean_truth - T.linear() * mean_estimate;
    return T;
}

double AbsoluteTrajectoryRmse(const std::vector<core::Transform>& estimate,
                              const std::vector<core::Transform>& truth) {
    RequireSameSize(estimate.size(), truth.size());
    if (estimate.empty()) throw core::ConfigError("ATE of an empty trajectory");
    const std::vector<Eigen::Vector3d> p_estimate = Positions(estimate);
    const std::vector<Eigen::Vector3d> p_truth = Positions(truth);
    const core::Transform T_truth_estimate = AlignRigid(p_estimate, p_truth);
    double sum = 0.0;
    for (std::size_t i = 0; i < p_estimate.size(); ++i) {
        sum += (p_truth[i] - T_truth_estimate * p_estimate[i]).squaredNorm();
    }
    return std::sqrt(sum / static_cast<double>(p_estimate.size()));
}

TrajectoryRpe ComputeTrajectoryRpe(const std::vector<core::Transform>& estimate,
                                   const std::vector<core::Transform>& truth,
                                   const TrajectoryRpeConfig& config) {
    RequireSameSize(estimate.size(), truth.size());
    if (config.step == 0) throw core::ConfigError("the RPE step must be at least 1 pose");
    for (const double length : config.lengths_m) {
        if (!(length > 0.0)) throw core::ConfigError("RPE segment lengths must be positive");
    }
    // Ground-truth path length from pose 0 (the devkit's trajectoryDistances).
    std::vector<double> path(truth.size(), 0.0);
    for (std::size_t i = 1; i < truth.size(); ++i) {
        path[i] = path[i - 1] + (truth[i].translation() - truth[i - 1].translation()).norm();
    }
    TrajectoryRpe result;
    double translation_sum = 0.0;
    double rotation_sum = 0.0;
    for (std::size_t first = 0; first < truth.size(); first += config.step) {
        std::size_t last = first;
        for (const double length : config.lengths_m) {
            // Lengths need not be sorted: search from `first` each time.
            last = first;
            while (last < truth.size() && path[last] < path[first] + length) ++last;
            if (last >= truth.size()) continue;
            const core::Transform truth_delta = truth[first].inverse() * truth[last];
            const core::Transform estimate_delta = estimate[first].inverse() * estimate[last];
            const core::Transform error = truth_delta.inverse() * estimate_delta;
            translation_sum += error.translation().norm() / length;
            rotation_sum += Eigen::AngleAxisd(error.linear()).angle() / length;
            ++result.segments;
        }
    }
    if (result.segments == 0) {
        result.translation_percent = std::numeric_limits<double>::quiet_NaN();
        result.rotation_deg_per_100m = std::numeric_limits<double>::quiet_NaN();
        return result;
    }
    const double n = static_cast<double>(result.segments);
    result.translation_percent = 100.0 * translation_sum / n;
    result.rotation_deg_per_100m = 100.0 * (rotation_sum / n) * 180.0 / std::numbers::pi;
    return result;
}

}  // namespace lidarloop::eval

#include "lidarloop/registration/icp.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Cholesky>

namespace lidarloop::registration {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// The normal equations of one Gauss-Newton step, for increments (rotation, translation) applied
// on the left of the pose.
struct NormalEquations {
    Matrix6d hessian = Matrix6d::Zero();  // lower triangle only (AddLowerOuterProduct)
    Vector6d gradient = Vector6d::Zero();
    std::size_t count = 0;
    std::size_t paired = 0;   // query points given (within the cap)
    std::size_t inliers = 0;  // of those, within the inlier distance of a plane
};

// hessian += weighted * jacobian^T in the lower triangle only: the LDLT that solves the normal
// equations reads no other (Eigen's default), and each entry is the product Eigen's outer
// product forms, so the step is the same to the bit for 21 of the 36 products.
void AddLowerOuterProduct(const Vector6d& weighted, const Vector6d& jacobian, Matrix6d& hessian) {
    for (int j = 0; j < 6; ++j) {
        for (int i = j; i < 6; ++i) hessian(i, j) += weighted(i) * jacobian(j);
    }
}

// Pairs every stride-th point of `from` (an even subsample of at most `cap` points).
// `partners` holds each paired point's partner of the previous iteration (-1: none), the hint
// that makes the nearest-neighbour search cheap once the pose moves little; updated here.
void Accumulate(const SurfacePoints& from, const SurfacePoints& onto, const Eigen::Isometry3f& T,
                float max_distance_m, int cap, float inlier_m, std::vector<std::int64_t>& partners,
                NormalEquations& equations) {
    const double scale_m = max_distance_m / 3.0;
    const std::size_t stride = std::max<std::size_t>(1, (from.size() + cap - 1) / cap);
    partners.resize((from.size() + stride - 1) / stride, -1);
    // A point without a partner of its own takes the last point's as its hint: consecutive
    // points of a scan lie near each other, and a hint only bounds the search (exact either way).
    std::int64_t last_partner = -1;
    for (std::size_t i = 0, k = 0; i < from.size(); i += stride, ++k) {
        const Eigen::Vector3f& point = from.points()[i];
        ++equations.paired;
        const Eigen::Vector3f moved = T * point;
        const std::int64_t hint = partners[k] >= 0 ? partners[k] : last_partner;
        const auto index = onto.grid().NearestWithin(moved, max_distance_m, hint);
        partners[k] = index;
        if (index < 0) continue;
        last_partner = index;
        const Eigen::Vector3d normal =
            onto.normals()[static_cast<std::size_t>(index)].cast<double>();
        const Eigen::Vector3d q = moved.cast<double>();
        const double residual =
            normal.dot(q - onto.points()[static_cast<std::size_t>(index)].cast<double>());
        if (std::abs(residual) <= inlier_m) ++equations.inliers;
        // Geman-McClure weight: residuals far beyond the scale barely pull.
        const double ratio = residual / scale_m;
        const double weight = 1.0 / ((1.0 + ratio * ratio) * (1.0 + ratio * ratio));
        Vector6d jacobian;
        jacobian << q.cross(normal), normal;
        AddLowerOuterProduct(weight * jacobian, jacobian, equations.hessian);
        equations.gradient.noalias() += weight * residual * jacobian;
        ++equations.count;
    }
}

core::Transform Increment(const Vector6d& step) {
    core::Transform increment = core::Transform::Identity();
    const Eigen::Vector3d rotation = step.head<3>();
    const double angle_rad = rotation.norm();
    if (angle_rad > 0.0)
        increment.linear() = Eigen::AngleAxisd(angle_rad, rotation / angle_rad).toRotationMatrix();
    increment.translation() = step.tail<3>();
    return increment;
}

// Each paired query point's partner in the last iteration, structure and ground.
struct Partners {
    std::vector<std::int64_t> structure, ground;
};

// How far to move along `step` when it points within 37 degrees of the previous step (zero at a
// stage's start): steps that shrink by a ratio r would still add r + r^2 + ... = r / (1 - r) of
// this one, so the pose moves 1 / (1 - r) times it, at most IcpConfig::aligned_step_factor.
double StepFactor(const Vector6d& step, const Vector6d& previous, const IcpConfig& config) {
    constexpr double kAlignedCosine = 0.8;
    const double norms = step.norm() * previous.norm();
    if (config.aligned_step_factor == 1.0 || !(norms > 0.0) ||
        step.dot(previous) <= kAlignedCosine * norms)
        return 1.0;
    const double ratio = step.norm() / previous.norm();
    return ratio < 1.0 ? std::min(1.0 / (1.0 - ratio), config.aligned_step_factor)
                       : config.aligned_step_factor;
}

// One stage at a fixed correspondence distance, pairing at most the given query points; returns
// true when it settled.
bool RunStage(const PreparedScan& query, const PreparedScan& match, float max_distance_m,
              int structure_cap, int ground_cap, const IcpConfig& config, Partners& partners,
              IcpResult& result) {
    Vector6d previous = Vector6d::Zero();
    for (int iteration = 0; iteration < config.max_iterations_per_stage; ++iteration) {
        NormalEquations equations;
        const Eigen::Isometry3f T = result.T_match_query.cast<float>();
        const auto inlier_m = static_cast<float>(config.final_correspondence_m);
        Accumulate(*query.structure, *match.structure, T, max_distance_m, structure_cap, inlier_m,
                   partners.structure, equations);
        result.structure_inliers =
            equations.paired == 0
                ? 0.0
                : static_cast<double>(equations.inliers) / static_cast<double>(equations.paired);
        Accumulate(*query.ground, *match.ground, T, max_distance_m, ground_cap, inlier_m,
                   partners.ground, equations);
        ++result.iterations;
        result.correspondences = equations.count;
        if (equations.count < 6) return false;
        const Vector6d step = equations.hessian.ldlt().solve(-equations.gradient);
        if (!step.allFinite()) return false;
        result.T_match_query =
            Increment(StepFactor(step, previous, config) * step) * result.T_match_query;
        previous = step;
        if (step.head<3>().norm() + step.tail<3>().norm() < config.convergence_step) return true;
    }
    return false;
}

}  // namespace

IcpResult RefinePointToPlane(const PreparedScan& query, const PreparedScan& match,
                             const core::Transform& T_initial, const IcpConfig& config,
                             const std::function<bool(const core::Transform&)>& keep_going) {
    IcpResult result;
    result.T_match_query = T_initial;
    double distance_m = config.initial_correspondence_m;
    Partners partners;
    while (true) {
        const bool first = distance_m == config.initial_correspondence_m;
        // Thinned only when finer stages follow, which pair every point.
        const bool thinned = first && distance_m > config.final_correspondence_m;
        const auto cap = [thinned](int first_stage_points, int points) {
            return thinned ? std::min(first_stage_points, points) : points;
        };
        const int structure_cap =
            cap(config.first_stage_structure_points, config.max_structure_points);
        const int ground_cap = cap(config.first_stage_ground_points, config.max_ground_points);
        result.converged = RunStage(query, match, static_cast<float>(distance_m), structure_cap,
                                    ground_cap, config, partners, result);
        // The later stages pair every point, another subsample: their hints start afresh.
        if (structure_cap != config.max_structure_points) partners.structure.clear();
        if (ground_cap != config.max_ground_points) partners.ground.clear();
        if (distance_m <= config.final_correspondence_m) break;
        if (first && keep_going && !keep_going(result.T_match_query)) {
            result.abandoned = true;
            result.converged = false;
            break;
        }
        distance_m = std::max(config.final_correspondence_m, distance_m / 2.0);
    }
    return result;
}

}  // namespace lidarloop::registration

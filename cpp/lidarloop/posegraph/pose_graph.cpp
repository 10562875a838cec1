
#include "lidarloop/posegraph/pose_graph.hpp"
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include "lidarloop/core/angles.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/min_gap.hpp"

namespace lidarloop::posegraph {
namespace {}  // namespace

Vector6d EdgeError(const core::Transform& T_from_to, const core::Transform& T_world_from,
                   const core::Transform& T_world_to) {
    const core::Transform delta = T_from_to.inverse() * T_world_from.inverse() * T_world_to;
    Eigen::Quaterniond q(delta.linear());
    q.normalize();
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();
    Vector6d error;
    error << delta.translation(), q.vec();
    return error;
}

Matrix6d DiagonalInformation(double sigma_t_m, double sigma_r_rad) {
    Vector6d diagonal;
    const double t = 1.0 / (sigma_t_m * sigma_t_m);
    const double r = 4.0 / (sigma_r_rad * sigma_r_rad);
    diagonal << t, t, t, r, r, r;
    return diagonal.asDiagonal();
}

Matrix6d OdometryInformation(const core::Transform& T_prev_next, const InformationConfig& config,
                             double length_m) {
    if (std::isnan(length_m)) length_m = T_prev_next.translation().norm();
    const double a_t = config.odometry_translation_sigma_m_per_sqrt_m;
    const double a_r = config.odometry_rotation_sigma_deg_per_sqrt_m * core::kRadiansPerDegree;
    const double min_t = config.odometry_min_translation_sigma_m;
    const double min_r = config.odometry_min_rotation_sigma_deg * core::kRadiansPerDegree;
    return DiagonalInformation(std::sqrt(min_t * min_t + a_t * a_t * length_m),
                               std::sqrt(min_r * min_r + a_r * a_r * length_m));
}

Matrix6d LoopInformation(const LoopConstraint& loop, const InformationConfig& config) {
    const double rmse_m = std::isfinite(loop.rmse_m) ? loop.rmse_m : 0.0;
    const double overlap =
        std::isfinite(loop.overlap) ? loop.overlap : config.loop_reference_overlap;
    const double weight = std::clamp(overlap / config.loop_reference_overlap, 0.2, 2.0);
    const double sigma_t = std::hypot(config.loop_translation_sigma_m, rmse_m);
    return weight *
           DiagonalInformation(sigma_t, config.loop_rotation_sigma_deg * core::kRadiansPerDegree);
}

void RequireEdgesWithin(const std::vector<Edge>& edges, std::size_t pose_count) {
    for (const Edge& edge : edges) {
        if (edge.from >= pose_count || edge.to >= pose_count) {
            throw core::ConfigError("an edge joins poses " + std::to_string(edge.from) + " and " +
                                    std::to_string(edge.to) + " of a graph of " +
                                    std::to_string(pose_count));
        }
    }
}

PoseGraph BuildPoseGraph(const std::vector<core::Transform>& odometry,
                         const std::vector<LoopConstraint>& loops, const PoseGraphConfig& config,
                         std::vector<double> path_m) {
    config.Validate();
    if (!path_m.empty() && path_m.size() != odometry.size()) {
        throw core::ConfigError("the pose graph's path has " + std::to_string(path_m.size()) +
                                " lengths for " + std::to_string(odometry.size()) + " poses");
    }
    core::CheckPathM(path_m, "the pose graph's path");
    PoseGraph graph;
    graph.poses = odometry;
    graph.path_m = std::move(path_m);
    graph.edges.reserve(odometry.size() + loops.size());
    for (std::size_t i = 0; i + 1 < odometry.size(); ++i) {
        Edge edge;
        edge.from = i;
        edge.to = i + 1;
        edge.T_from_to = odometry[i].inverse() * odometry[i + 1];
        edge.information =
            OdometryInformation(edge.T_from_to, config.information,
                                graph.path_m.empty() ? std::numeric_limits<double>::quiet_NaN()
                                                     : graph.path_m[i + 1] - graph.path_m[i]);
        graph.edges.push_back(edge);
    }
    for (std::size_t k = 0; k < loops.size(); ++k) {
        const LoopConstraint& loop = loops[k];
        if (loop.query >= odometry.size() || loop.match >= odometry.size()) {
            throw core::ConfigError("loop " + std::to_string(k) + " (query " +
                                    std::to_string(loop.query) + ", match " +
                                    std::to_string(loop.match) + ") names a scan outside the " +
                                    std::to_string(odometry.size()) + " poses");
        }
        if (loop.query == loop.match) {
            throw core::ConfigError("loop " + std::to_string(k) + " joins scan " +
                                    std::to_string(loop.query) + " to itself");
        }
        Edge edge;
        edge.kind = Edge::Kind::kLoop;
        edge.from = loop.match;
        edge.to = loop.query;
        edge.T_from_to = loop.T_match_query;
        edge.information = LoopInformation(loop, config.information);
        edge.loop = k;
        graph.edges.push_back(edge);
    }
    return graph;
}

}  // namespace lidarloop::posegraph

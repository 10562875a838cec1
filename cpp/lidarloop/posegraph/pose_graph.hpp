#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/posegraph/pose_graph_config.hpp"

namespace lidarloop::posegraph {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// An accepted loop: scan `query` seen from scan `match` (both indices into the trajectory).
struct LoopConstraint {
    std::size_t query = 0;
    std::size_t match = 0;
    core::Transform T_match_query = core::Transform::Identity();  ///< query -> match frame
    /// The verification's smaller overlap fraction, (0, 1]; NaN when unknown.
    double overlap = std::numeric_limits<double>::quiet_NaN();
    /// The verification's RMS plane distance, metres; NaN when unknown.
    double rmse_m = std::numeric_limits<double>::quiet_NaN();
};

/// A relative-pose measurement between two poses of the graph, in g2o's EDGE_SE3:QUAT
/// convention: T_from_to is the pose of `to` in the frame of `from`, and the error of estimates
/// T_world_from, T_world_to is EdgeError (translation, then the quaternion's x y z), to which
/// `information` (6x6, symmetric positive definite) belongs.
struct Edge {
    enum class Kind { kOdometry, kLoop };
    Kind kind = Kind::kOdometry;
    std::size_t from = 0;
    std::size_t to = 0;
    core::Transform T_from_to = core::Transform::Identity();
    Matrix6d information = Matrix6d::Identity();
    std::size_t loop = 0;  ///< kLoop: index into the loops the graph was built from
};

/// Poses T_world_sensor (the initial estimate: the odometry) and the edges between them.
struct PoseGraph {
    std::vector<core::Transform> poses;
    std::vector<Edge> edges;
    /// Per pose, metres travelled from pose 0 (the odometry's path, core::CumulativePathM):
    /// what the odometry's drift grows with. Empty: the straight steps between the poses.
    std::vector<double> path_m;
};

/// g2o's EDGE_SE3:QUAT error: with delta = T_from_to^-1 * T_world_from^-1 * T_world_to, the
/// translation of delta (metres, in the measured `to` frame) and the vector part x y z of its
/// unit quaternion taken with w >= 0 (sin(angle / 2) times the axis). Zero when the estimates
/// agree with the measurement.
Vector6d EdgeError(const core::Transform& T_from_to, const core::Transform& T_world_from,
                   const core::Transform& T_world_to);

/// The information of an error of translation sigma_t (metres, per axis) and rotation sigma_r
/// (radians, per axis): diag(1/sigma_t^2 x3, 4/sigma_r^2 x3) (the quaternion's vector part is
/// half the rotation angle).
Matrix6d DiagonalInformation(double sigma_t_m, double sigma_r_rad);

/// The information of an odometry step T_prev_next (InformationConfig) over `length_m` of path;
/// NaN: the step's straight line.
Matrix6d OdometryInformation(const core::Transform& T_prev_next, const InformationConfig& config,
                             double length_m = std::numeric_limits<double>::quiet_NaN());

/// The information of a loop from its verification quality (InformationConfig).
Matrix6d LoopInformation(const LoopConstraint& loop, const InformationConfig& config);

/// Throws core::ConfigError when an edge of `edges` joins a pose beyond the first `pose_count`:
/// a solver would index past its poses, a g2o file would get a new, free vertex.
void RequireEdgesWithin(const std::vector<Edge>& edges, std::size_t pose_count);

/// The graph of a trajectory: one pose per scan (`odometry`, T_world_sensor), an odometry edge
/// from every scan to the next (their relative pose), and an edge from match to query for every
/// loop. `path_m`: per pose, the path travelled (PoseGraph::path_m), longer than the straight
/// steps when the poses are some frames of a longer trajectory; empty: the straight steps.
/// Throws core::ConfigError when a loop names a scan outside the trajectory or the same scan
/// twice, `path_m` has another size than `odometry`, or `config` is invalid.
PoseGraph BuildPoseGraph(const std::vector<core::Transform>& odometry,
                         const std::vector<LoopConstraint>& loops, const PoseGraphConfig& config,
                         std::vector<double> path_m = {});

}  // namespace lidarloop::posegraph

#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/posegraph/pose_graph.hpp"
#include "lidarloop/posegraph/pose_graph_config.hpp"

namespace lidarloop::posegraph {

/// What the back end did with a loop.
enum class LoopVerdict {
    kUsed,                ///< in the optimised graph
    kRejectedByOdometry,  ///< inconsistent with the odometry beyond its drift (the gate)
    kRejectedByResidual,  ///< inconsistent with the optimised graph (whitened residual too large)
    /// without a consistent neighbouring loop, and inconsistent with the optimised graph
    kRejectedByConsistency,
};

/// "used", "rejected_by_odometry", "rejected_by_residual", "rejected_by_consistency".
std::string ToString(LoopVerdict verdict);

/// One loop edge of the graph and the back end's verdict on it.
struct LoopResult {
    std::size_t loop = 0;  ///< Edge::loop: index into the loops the graph was built from
    LoopVerdict verdict = LoopVerdict::kUsed;
    double path_m = 0.0;  ///< odometry path length between its two scans
    /// How far the loop's transform is from the odometry's relative pose of its scans, and the
    /// gate's tolerance at path_m (RobustConfig).
    double odometry_translation_error_m = 0.0;
    double odometry_rotation_error_deg = 0.0;
    double gate_translation_m = 0.0;
    double gate_rotation_deg = 0.0;
    /// sqrt(e^T Omega e) of the loop at the odometry and at the final estimate (the last solve
    /// it took part in; NaN when the gate rejected it).
    double initial_whitened_residual = 0.0;
    double whitened_residual = 0.0;
    std::size_t support = 0;  ///< consistent neighbouring loops (RobustConfig::min_support)
};

struct OptimisationResult {
    std::vector<core::Transform> poses;  ///< optimised T_world_sensor, one per graph pose
    std::vector<LoopResult> loops;       ///< one per loop edge, in the order of graph.edges
    std::size_t loops_used = 0;
    std::size_t rejected_by_odometry = 0;
    std::size_t rejected_by_residual = 0;
    std::size_t rejected_by_consistency = 0;
    int solves = 0;             ///< Ceres solves (graduated rounds and re-solves after rejections)
    int iterations = 0;         ///< trust-region (dogleg) iterations over all solves
    bool converged = true;      ///< every solve ended by a convergence test, not the limit
    double initial_cost = 0.0;  ///< 1/2 sum of squared whitened errors at the odometry, used
                                ///< loops only, without loss function
    double final_cost = 0.0;    ///< the same at the optimised poses
    double seconds = 0.0;
    std::string note;  ///< e.g. why the odometry came back unchanged; empty otherwise
};

/// The translation discrepancy (metres) GateAgainstOdometry lets pass over `path_m` of path:
/// nondecreasing in path_m.
double GateTranslationM(double path_m, const PoseGraphConfig& config);
/// The rotation discrepancy (degrees) GateAgainstOdometry lets pass over `path_m` of path:
/// nondecreasing in path_m.
double GateRotationDeg(double path_m, const PoseGraphConfig& config);

/// The odometry gate (RobustConfig) for one loop: `T_from_to_loop`, the loop's transform between
/// two scans, against `T_from_to_odometry`, the odometry's relative pose of the same scans, with
/// the drift the information model allows over `path_m` of path between them. Fills path_m, the
/// errors and tolerances; verdict kRejectedByOdometry when an error exceeds its tolerance, else
/// kUsed. Optimise applies it to every loop first; `detect --odometry` to every accepted loop.
LoopResult GateAgainstOdometry(const core::Transform& T_from_to_loop,
                               const core::Transform& T_from_to_odometry, double path_m,
                               const PoseGraphConfig& config);

/// Optimises the graph with Ceres (trust region with Powell's dogleg, sparse Cholesky): every pose
/// is a position in R^3 and a unit quaternion (Ceres' ProductManifold of EuclideanManifold<3> and
/// EigenQuaternionManifold), pose 0 is fixed, and
/// every edge's error is EdgeError whitened by its information. Wrong loops are kept out in
/// four steps (docs/posegraph.md#robustness): the odometry gate; the support test against
/// neighbouring loops; a Cauchy loss on loop edges whose scale shrinks over graduated rounds;
/// then every loop is tested against the optimised graph (whitened residual <= reject_sigmas),
/// dropped or taken in, and the graph optimised again.
///
/// A graph without loop edges (or whose loops are all rejected by the gate) is returned
/// unchanged, with a note. Throws core::ConfigError for an invalid config, an empty graph or an
/// edge naming a pose that does not exist. Pure: no I/O; thread-safe for distinct graphs.
OptimisationResult Optimise(const PoseGraph& graph, const PoseGraphConfig& config);

/// When the back end rejected more than half of the loops of `result` (the outcome of Optimise
/// on `graph`), and at least 3: one line with the count, the main cause and what in the odometry
/// (graph.poses) may explain it, its largest step against the median step and its longest
/// standstill, e.g. "178 of 183 loops rejected, 178 of them against the odometry: does the odometry
/// reset or freeze? (largest step 45.2 m, median 0.9 m, from scan 811 to 812; longest standstill:
/// scans 300 to 420)". Empty otherwise.
std::string SummariseRejections(const PoseGraph& graph, const OptimisationResult& result);

}  // namespace lidarloop::posegraph

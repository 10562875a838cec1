#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "lidarloop/app/progress.hpp"
#include "lidarloop/eval/trajectory.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/posegraph/optimiser.hpp"

namespace lidarloop::app {

/// The file format of poses_optimised.txt.
enum class PoseFormat { kKitti, kTum };

/// What `lidarloop optimise` asks for.
struct OptimiseRequest {
    io::RunConfig config;  ///< `posegraph`; without a loops file also how loops are detected
    std::filesystem::path odometry_file;  ///< KITTI or TUM, one pose per scan (T_world_sensor)
    /// Instead of odometry_file, for a bag: its nav_msgs/Odometry topic, matched to the scans by
    /// their stamps (ReadOdometry).
    std::string odometry_topic;
    std::filesystem::path odometry_calib;  ///< as DetectRequest::odometry_calib
    /// Accepted loops with their T_match_query (loops.csv of `detect` with verification). Empty:
    /// RunDetect with verification runs first, into out/detection.
    std::filesystem::path loops_file;
    PoseFormat format = PoseFormat::kKitti;
    /// With ground truth, a loop is true when its transform is within these of the ground
    /// truth's relative pose of its scans (for the plot, the report and metrics.json).
    double true_loop_translation_m = 2.0;
    double true_loop_rotation_deg = 5.0;
    bool skip_bad = false;  ///< for the detection run
    Progress progress;
    std::filesystem::path out;  ///< the results folder (created)
};

/// ATE and RPE of one trajectory against the ground truth.
struct TrajectoryMetrics {
    double ate_rmse_m = 0.0;
    eval::TrajectoryRpe rpe;
};

/// The maps optimise writes: all scans placed with the odometry and with the optimised poses.
struct MapSummary {
    std::size_t odometry_points = 0;   ///< points of map_odometry.ply
    std::size_t optimised_points = 0;  ///< points of map_optimised.ply
    double voxel_m = 0.0;              ///< voxel edge used (map.voxel_m, or coarser when capped)
    double seconds = 0.0;              ///< building and writing both maps and map.png
};

struct OptimiseOutcome {
    std::vector<posegraph::LoopConstraint> loops;  ///< the accepted loops, as read or detected
    posegraph::OptimisationResult result;
    /// Per loop: true, judged against the ground truth (empty without ground truth).
    std::vector<bool> loop_is_true;
    std::optional<TrajectoryMetrics> odometry;   ///< with ground truth
    std::optional<TrajectoryMetrics> optimised;  ///< with ground truth
    MapSummary maps;
    std::vector<std::string> notes;  ///< e.g. no loop, no ground truth, no gnuplot
    double total_s = 0.0;
};

/// The verified loops of `query` the pose graph takes (posegraph.max_loops_per_scan and
/// min_loop_separation_m), as indices into its candidates: the query's loop (LoopQuery::loop)
/// first, then the other accepted candidates by score (the earlier on a tie) whose match lies at
/// least min_loop_separation_m of `path_m` from every match taken. Empty without a verified
/// loop; only the loop when `path_m` is empty.
std::vector<std::size_t> LoopsForPoseGraph(const pipeline::LoopQuery& query,
                                           const std::vector<double>& path_m,
                                           const posegraph::PoseGraphConfig& config);

/// With detection.stop_at_first_loop, the candidates of a query with a loop that may still add
/// one LoopsForPoseGraph takes: while fewer than max_loops_per_scan candidates ranked before it
/// are accepted, one whose match lies at least min_loop_separation_m of `path_m` from each of
/// theirs. Empty (no more) when `path_m` is empty. `path_m` is referenced, not copied.
pipeline::MoreLoopsWanted PoseGraphLoopsWanted(const std::vector<double>& path_m,
                                               const posegraph::PoseGraphConfig& config);

/// Reads the odometry (io::ReadError naming the file when its pose count differs from the
/// dataset's scan count; the pose readers name the line of a non-finite value, a 3x3 part that
/// is no rotation, a time that does not increase or a step above posegraph.max_odometry_step_m) and
/// the loops (io::ReadLoopsCsv: a scan that does not exist or a value out of its range names the
/// line; rows repeating an earlier row's two scans, in either order, are merged into it, with a
/// note), or detects them, builds and optimises the pose graph, and writes into request.out:
/// poses_optimised.txt, graph.g2o (optimised vertices, the odometry edges and the loops used;
/// rejected loops commented), loop_verdicts.csv, metrics.json, report.md, config.yaml,
/// map_odometry.ply and map_optimised.ply (every scan placed with each trajectory, config.map;
/// io::WriteMapPly), map.png (their top views side by side, io::MapTopView) and, when gnuplot is
/// installed, trajectory.png (top view of the trajectories).
OptimiseOutcome RunOptimisation(const io::Dataset& dataset, const OptimiseRequest& request);

}  // namespace lidarloop::app

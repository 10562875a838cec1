#include "lidarloop/app/optimisation.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <set>
#include <string>
#include <utility>

#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/map_building.hpp"
#include "lidarloop/app/optimisation_report.hpp"
#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/io/map_files.hpp"
#include "lidarloop/io/map_image.hpp"
#include "lidarloop/io/png.hpp"
#include "lidarloop/io/pose_graph_files.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::app {
namespace {

// Whether two loops of one scan are far enough apart in path for the pose graph to take both. An
// unknown (NaN) path separates nothing.
bool SeparatedInPath(double a_m, double b_m, const posegraph::PoseGraphConfig& config) {
    return std::abs(a_m - b_m) >= config.min_loop_separation_m;
}

// The accepted loops of a detection run with verification (the verified candidate's pose).
std::vector<posegraph::LoopConstraint> DetectLoops(const io::Dataset& dataset,
                                                   const OptimiseRequest& request) {
    DetectRequest detect;
    detect.config = request.config;  // verify: RunOptimisation refuses detection.verify false
    detect.skip_bad = request.skip_bad;
    detect.progress = request.progress;
    detect.out = request.out / "detection";
    detect.odometry_file = request.odometry_file;  // the path a gap in metres is measured on
    detect.odometry_topic = request.odometry_topic;
    detect.odometry_calib = request.odometry_calib;
    detect.pose_graph_loops = true;
    const DetectOutcome detected = RunDetect(dataset, detect);
    std::vector<posegraph::LoopConstraint> loops;
    for (const pipeline::LoopQuery& query : detected.queries) {
        if (!query.accepted) continue;
        for (const std::size_t rank :
             LoopsForPoseGraph(query, detected.path_m, request.config.posegraph)) {
            const registration::Verification& v = query.verifications[rank];
            loops.push_back({query.query, query.candidates[rank].index, v.T_match_query,
                             v.overlap.Min(), v.overlap.rmse_m});
        }
    }
    return loops;
}

}  // namespace

std::vector<std::size_t> LoopsForPoseGraph(const pipeline::LoopQuery& query,
                                           const std::vector<double>& path_m,
                                           const posegraph::PoseGraphConfig& config) {
    const std::optional<std::size_t> best = query.loop();
    if (!best || !query.verified()) return {};
    std::vector<std::size_t> taken{*best};
    if (path_m.empty()) return taken;
    std::vector<std::size_t> others;
    for (std::size_t c = 0; c < query.verifications.size(); ++c) {
        if (c != *best && query.verifications[c].accepted) others.push_back(c);
    }
    std::stable_sort(others.begin(), others.end(), [&](std::size_t a, std::size_t b) {
        return query.verifications[a].score() > query.verifications[b].score();
    });
    const auto path_of = [&](std::size_t c) { return path_m.at(query.candidates[c].index); };
    for (const std::size_t c : others) {
        if (taken.size() >= static_cast<std::size_t>(config.max_loops_per_scan)) break;
        const bool separated = std::all_of(taken.begin(), taken.end(), [&](std::size_t t) {
            return SeparatedInPath(path_of(c), path_of(t), config);
        });
        if (separated) taken.push_back(c);
    }
    return taken;
}

pipeline::MoreLoopsWanted PoseGraphLoopsWanted(const std::vector<double>& path_m,
                                               const posegraph::PoseGraphConfig& config) {
    if (path_m.empty()) return {};
    return [&path_m, config](const pipeline::LoopQuery& query, std::size_t candidate) {
        const auto path_of = [&](std::size_t c) { return path_m.at(query.candidates[c].index); };
        std::size_t accepted = 0;
        for (std::size_t c = 0; c < candidate; ++c) {
            if (!query.verifications[c].accepted) continue;
            if (!SeparatedInPath(path_of(c), path_of(candidate), config)) return false;
            ++accepted;
        }
        return accepted < static_cast<std::size_t>(config.max_loops_per_scan);
    };
}

namespace {

// "lines 5, 6, 7 and 3 more" for a note.
std::string LineList(const std::vector<std::size_t>& lines) {
    constexpr std::size_t kShown = 5;
    std::string text = lines.size() == 1 ? "line " : "lines ";
    for (std::size_t k = 0; k < std::min(lines.size(), kShown); ++k) {
        text += (k == 0 ? "" : ", ") + std::to_string(lines[k]);
    }
    if (lines.size() > kShown) text += " and " + std::to_string(lines.size() - kShown) + " more";
    return text;
}

// The loops of a loops.csv, one per pair of scans. A repeated row (the same query and match, or
// the two swapped: the same constraint inverted, between the same two poses) is one measurement;
// counted n times it weighs n times (one wrong loop repeated 20 times pushed 22 true loops out of
// the graph). The first row is kept: detect writes one row per query, so repeats come from
// concatenated or edited files, and ranking them by their overlap or RMSE would let a wrong row
// that claims a better fit replace a right one.
std::vector<posegraph::LoopConstraint> ReadLoops(const io::Dataset& dataset,
                                                 const OptimiseRequest& request,
                                                 std::vector<std::string>& notes) {
    std::vector<posegraph::LoopConstraint> loops;
    std::set<std::pair<std::size_t, std::size_t>> pairs;  // (smaller scan, larger scan)
    std::vector<std::size_t> merged_lines;
    for (const io::LoopRow& row : io::ReadLoopsCsv(request.loops_file, dataset.size())) {
        const std::size_t query = row.loop.query, match = row.loop.match;
        if (query == match) {
            throw io::ReadError(request.loops_file, "line " + std::to_string(row.line) +
                                                        ": a loop from scan " +
                                                        std::to_string(query) + " to itself");
        }
        if (!pairs.emplace(std::min(query, match), std::max(query, match)).second) {
            merged_lines.push_back(row.line);
            continue;
        }
        loops.push_back(row.loop);
    }
    if (!merged_lines.empty()) {
        notes.push_back(std::to_string(merged_lines.size()) + " duplicate row" +
                        (merged_lines.size() == 1 ? "" : "s") + " of " +
                        request.loops_file.filename().string() +
                        " merged (the same two scans as an earlier row, in either order; " +
                        LineList(merged_lines) + "): each loop is used once, as first given");
    }
    return loops;
}

std::vector<posegraph::LoopConstraint> LoadLoops(const io::Dataset& dataset,
                                                 const OptimiseRequest& request,
                                                 std::vector<std::string>& notes) {
    if (request.loops_file.empty()) return DetectLoops(dataset, request);
    return ReadLoops(dataset, request, notes);
}

std::vector<core::Transform> Transforms(const std::vector<core::StampedPose>& poses) {
    std::vector<core::Transform> transforms;
    transforms.reserve(poses.size());
    for (const auto& pose : poses) transforms.push_back(pose.T_world_sensor);
    return transforms;
}

std::vector<bool> JudgeLoops(const std::vector<posegraph::LoopConstraint>& loops,
                             const std::vector<core::Transform>& truth,
                             const OptimiseRequest& request) {
    std::vector<bool> is_true;
    for (const auto& loop : loops) {
        const core::Transform error =
            (truth[loop.match].inverse() * truth[loop.query]).inverse() * loop.T_match_query;
        const double angle_deg =
            Eigen::AngleAxisd(error.linear()).angle() * 180.0 / std::numbers::pi;
        is_true.push_back(error.translation().norm() <= request.true_loop_translation_m &&
                          angle_deg <= request.true_loop_rotation_deg);
    }
    return is_true;
}

TrajectoryMetrics Measure(const std::vector<core::Transform>& estimate,
                          const std::vector<core::Transform>& truth) {
    return {eval::AbsoluteTrajectoryRmse(estimate, truth),
            eval::ComputeTrajectoryRpe(estimate, truth)};
}

void WritePoses(const std::filesystem::path& file, const OptimiseRequest& request,
                const std::vector<core::StampedPose>& odometry,
                const std::vector<core::Transform>& optimised) {
    std::vector<core::StampedPose> poses = odometry;  // keeps the times
    for (std::size_t i = 0; i < poses.size(); ++i) poses[i].T_world_sensor = optimised[i];
    if (request.format == PoseFormat::kTum) {
        io::WriteTumPoses(file, poses);
    } else {
        io::WriteKittiPoses(file, poses);
    }
}

void WriteGraph(const std::filesystem::path& file, const posegraph::PoseGraph& graph,
                const posegraph::OptimisationResult& result) {
    std::vector<posegraph::Edge> used;
    std::vector<posegraph::Edge> rejected;
    std::size_t loop = 0;
    for (const posegraph::Edge& edge : graph.edges) {
        const bool is_loop = edge.kind == posegraph::Edge::Kind::kLoop;
        if (is_loop && result.loops[loop++].verdict != posegraph::LoopVerdict::kUsed) {
            rejected.push_back(edge);
        } else {
            used.push_back(edge);
        }
    }
    io::WriteG2o(file, result.poses, used, rejected);
}

// The scans placed with the odometry and with the optimised poses, in one pass over the scans.
MapSummary WriteMaps(const io::Dataset& dataset, const OptimiseRequest& request,
                     const std::filesystem::path& out,
                     const std::vector<core::StampedPose>& odometry,
                     const std::vector<core::Transform>& optimised,
                     std::vector<std::string>& notes) {
    const Stopwatch watch;
    std::vector<core::StampedPose> placed = odometry;  // keeps the times
    for (std::size_t i = 0; i < placed.size(); ++i) placed[i].T_world_sensor = optimised[i];
    MapBuildOptions options;
    options.skip_bad = request.skip_bad;
    options.progress = request.progress;
    const BuiltMaps built = BuildMaps(dataset, {odometry, placed}, request.config.map, options);
    const core::MapCloud& before = built.maps[0];
    const core::MapCloud& after = built.maps[1];
    io::WriteMapPly(out / "map_odometry.ply", before);
    io::WriteMapPly(out / "map_optimised.ply", after);
    io::WritePng(out / "map.png", io::MapTopView({{"odometry", &before}, {"optimised", &after}}));
    if (!built.skipped.empty()) {
        notes.push_back("the maps leave out " + std::to_string(built.skipped.size()) +
                        " unreadable scans (" + built.skipped.front() + ", ...)");
    }
    for (const core::MapCloud* map : {&before, &after}) {
        const std::string note = CoarsenedMapNote(*map, request.config.map);
        if (!note.empty()) notes.push_back(note);
    }
    return {before.points.size(), after.points.size(), std::max(before.voxel_m, after.voxel_m),
            watch.Seconds()};
}

}  // namespace

OptimiseOutcome RunOptimisation(const io::Dataset& dataset, const OptimiseRequest& request) {
    Stopwatch total;
    request.config.Validate();
    if (request.loops_file.empty() && !request.config.detection.verify) {
        throw core::ConfigError(
            "optimise verifies the loops it detects (the pose graph needs their poses): "
            "detection.verify: false is for detect, evaluate and bench");
    }
    const std::filesystem::path out = PrepareOutputFolder(request.out);
    io::WriteConfigYaml(out / "config.yaml", request.config);
    const std::vector<core::StampedPose> odometry =
        ReadOdometry(request.odometry_file, request.odometry_topic, dataset,
                     request.config.posegraph.max_odometry_step_m, request.odometry_calib);
    OptimiseOutcome outcome;
    outcome.loops = LoadLoops(dataset, request, outcome.notes);
    const posegraph::PoseGraph graph =
        posegraph::BuildPoseGraph(Transforms(odometry), outcome.loops, request.config.posegraph,
                                  core::CumulativePathM(odometry));
    outcome.result = posegraph::Optimise(graph, request.config.posegraph);
    if (!outcome.result.note.empty()) outcome.notes.push_back(outcome.result.note);
    const std::string rejections = posegraph::SummariseRejections(graph, outcome.result);
    if (!rejections.empty()) outcome.notes.push_back(rejections);
    if (dataset.HasPoses()) {
        const std::vector<core::Transform> truth = Transforms(dataset.poses());
        outcome.loop_is_true = JudgeLoops(outcome.loops, truth, request);
        outcome.odometry = Measure(graph.poses, truth);
        outcome.optimised = Measure(outcome.result.poses, truth);
    } else {
        outcome.notes.push_back("the dataset has no ground-truth poses: no ATE or RPE");
    }
    WritePoses(out / "poses_optimised.txt", request, odometry, outcome.result.poses);
    WriteGraph(out / "graph.g2o", graph, outcome.result);
    WriteLoopVerdicts(out / "loop_verdicts.csv", outcome);
    outcome.maps = WriteMaps(dataset, request, out, odometry, outcome.result.poses, outcome.notes);
    const std::vector<core::Transform> truth =
        dataset.HasPoses() ? Transforms(dataset.poses()) : std::vector<core::Transform>{};
    if (const auto note = DrawTrajectoryPlot(out / "trajectory.png", graph.poses, truth, outcome))
        outcome.notes.push_back(*note);
    outcome.total_s = total.Seconds();
    WriteJson(out / "metrics.json", OptimisationMetricsJson(dataset, request, outcome));
    WriteOptimisationReport(out / "report.md", dataset, request, outcome);
    return outcome;
}

}  // namespace lidarloop::app

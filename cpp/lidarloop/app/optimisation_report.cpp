#include "lidarloop/app/optimisation_report.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "lidarloop/app/detection.hpp"
#include "lidarloop/io/plot.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::app {
namespace {

std::string Rounded(double value, int digits = 4) {
    if (!std::isfinite(value)) return "–";
    char text[64];
    std::snprintf(text, sizeof(text), "%.*g", digits, value);
    return text;
}

std::optional<bool> IsTrue(const OptimiseOutcome& outcome, std::size_t loop) {
    if (outcome.loop_is_true.empty()) return std::nullopt;
    return outcome.loop_is_true[loop];
}

io::PlotSeries Trajectory(const std::string& title, const std::vector<core::Transform>& poses) {
    io::PlotSeries series{title, {}, {}, io::PlotSeries::Style::kLines};
    for (const auto& pose : poses) {
        series.x.push_back(pose.translation().x());
        series.y.push_back(pose.translation().y());
    }
    return series;
}

// Segments from match to query on `poses`, separated by NaN (gnuplot breaks the line there).
void AddSegment(io::PlotSeries& series, const core::Transform& a, const core::Transform& b) {
    constexpr double kBreak = std::numeric_limits<double>::quiet_NaN();
    series.x.insert(series.x.end(), {a.translation().x(), b.translation().x(), kBreak});
    series.y.insert(series.y.end(), {a.translation().y(), b.translation().y(), kBreak});
}

std::size_t CountTrue(const OptimiseOutcome& outcome, bool used_only) {
    std::size_t count = 0;
    for (std::size_t k = 0; k < outcome.loop_is_true.size(); ++k) {
        const bool used = outcome.result.loops[k].verdict == posegraph::LoopVerdict::kUsed;
        count += outcome.loop_is_true[k] && (used || !used_only) ? 1 : 0;
    }
    return count;
}

nlohmann::json TrajectoryJson(const std::optional<TrajectoryMetrics>& metrics) {
    if (!metrics) return nullptr;
    return {{"ate_rmse_m", metrics->ate_rmse_m},
            {"rpe_translation_percent", metrics->rpe.translation_percent},
            {"rpe_rotation_deg_per_100m", metrics->rpe.rotation_deg_per_100m},
            {"rpe_segments", metrics->rpe.segments}};
}

double Field(const std::optional<TrajectoryMetrics>& m, double TrajectoryMetrics::*field) {
    return m ? (*m).*field : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

void WriteLoopVerdicts(const std::filesystem::path& file, const OptimiseOutcome& outcome) {
    std::ofstream out(file);
    out << "query,match,verdict,true,path_m,odometry_translation_error_m,"
           "odometry_rotation_error_deg,gate_translation_m,gate_rotation_deg,"
           "initial_whitened_residual,whitened_residual\n";
    out.precision(6);
    for (std::size_t k = 0; k < outcome.result.loops.size(); ++k) {
        const posegraph::LoopResult& r = outcome.result.loops[k];
        const posegraph::LoopConstraint& loop = outcome.loops[r.loop];
        const std::optional<bool> is_true = IsTrue(outcome, r.loop);
        out << loop.query << ',' << loop.match << ',' << posegraph::ToString(r.verdict) << ','
            << (is_true ? (*is_true ? "1" : "0") : "") << ',' << r.path_m << ','
            << r.odometry_translation_error_m << ',' << r.odometry_rotation_error_deg << ','
            << r.gate_translation_m << ',' << r.gate_rotation_deg << ','
            << r.initial_whitened_residual << ',';
        if (std::isfinite(r.whitened_residual)) out << r.whitened_residual;
        out << '\n';
    }
    if (!out) throw io::WriteError(file, "writing failed");
}

std::optional<std::string> DrawTrajectoryPlot(const std::filesystem::path& png,
                                              const std::vector<core::Transform>& odometry,
                                              const std::vector<core::Transform>& truth,
                                              const OptimiseOutcome& outcome) {
    if (!io::GnuplotAvailable()) return "gnuplot is not installed: no trajectory.png";
    io::Plot plot;
    plot.title = "Top view: loops drawn on the odometry, from match to query";
    plot.x_label = "x (m)";
    plot.y_label = "y (m)";
    plot.equal_axes = true;
    if (!truth.empty()) {
        plot.series.push_back(Trajectory("ground truth", truth));
        plot.colors.push_back("#222222");
    }
    plot.series.push_back(Trajectory("odometry", odometry));
    plot.series.push_back(Trajectory("optimised", outcome.result.poses));
    const bool judged = !outcome.loop_is_true.empty();
    io::PlotSeries good{judged ? "true loops" : "loops", {}, {}, io::PlotSeries::Style::kLines};
    io::PlotSeries bad{"false loops", {}, {}, io::PlotSeries::Style::kLines};
    io::PlotSeries rejected{
        "rejected by the back end (at the query)", {}, {}, io::PlotSeries::Style::kPoints};
    for (const posegraph::LoopResult& r : outcome.result.loops) {
        const posegraph::LoopConstraint& loop = outcome.loops[r.loop];
        const bool is_true = !judged || outcome.loop_is_true[r.loop];
        AddSegment(is_true ? good : bad, odometry[loop.match], odometry[loop.query]);
        if (r.verdict != posegraph::LoopVerdict::kUsed) {
            rejected.x.push_back(odometry[loop.query].translation().x());
            rejected.y.push_back(odometry[loop.query].translation().y());
        }
    }
    for (auto* series : {&good, &bad, &rejected}) plot.series.push_back(*series);
    for (const char* color : {"#e6ab02", "#1f78b4", "#33a02c", "#e31a1c", "#6a3d9a"})
        plot.colors.push_back(color);
    io::RenderPlot(png, plot);
    return std::nullopt;
}

nlohmann::json OptimisationMetricsJson(const io::Dataset& dataset, const OptimiseRequest& request,
                                       const OptimiseOutcome& outcome) {
    const posegraph::OptimisationResult& r = outcome.result;
    nlohmann::json rejected = nlohmann::json::array();
    for (const posegraph::LoopResult& loop : r.loops) {
        if (loop.verdict == posegraph::LoopVerdict::kUsed) continue;
        const std::optional<bool> is_true = IsTrue(outcome, loop.loop);
        rejected.push_back({{"query", outcome.loops[loop.loop].query},
                            {"match", outcome.loops[loop.loop].match},
                            {"verdict", posegraph::ToString(loop.verdict)},
                            {"true", is_true ? nlohmann::json(*is_true) : nullptr}});
    }
    nlohmann::json loops = {{"accepted", outcome.loops.size()},
                            {"used", r.loops_used},
                            {"rejected_by_odometry", r.rejected_by_odometry},
                            {"rejected_by_residual", r.rejected_by_residual},
                            {"rejected_by_consistency", r.rejected_by_consistency},
                            {"rejected", rejected}};
    if (!outcome.loop_is_true.empty()) {
        loops["true"] = CountTrue(outcome, false);
        loops["false"] = outcome.loops.size() - CountTrue(outcome, false);
        loops["false_used"] = r.loops_used - CountTrue(outcome, true);
    }
    return {{"dataset", dataset.root().string()},
            {"scans", dataset.size()},
            {"odometry", OdometryName(request.odometry_file, request.odometry_topic, dataset)},
            {"loops_file",
             request.loops_file.empty() ? "detection/loops.csv" : request.loops_file.string()},
            {"ate_rmse_m_odometry", Field(outcome.odometry, &TrajectoryMetrics::ate_rmse_m)},
            {"ate_rmse_m_optimised", Field(outcome.optimised, &TrajectoryMetrics::ate_rmse_m)},
            {"rpe_odometry", TrajectoryJson(outcome.odometry)},
            {"rpe_optimised", TrajectoryJson(outcome.optimised)},
            {"loops", loops},
            {"solver",
             {{"solves", r.solves},
              {"iterations", r.iterations},
              {"converged", r.converged},
              {"initial_cost", r.initial_cost},
              {"final_cost", r.final_cost},
              {"seconds", r.seconds}}},
            {"maps",
             {{"voxel_m", outcome.maps.voxel_m},
              {"points_odometry", outcome.maps.odometry_points},
              {"points_optimised", outcome.maps.optimised_points},
              {"seconds", outcome.maps.seconds}}},
            {"notes", outcome.notes},
            {"total_s", outcome.total_s}};
}

void WriteOptimisationReport(const std::filesystem::path& file, const io::Dataset& dataset,
                             const OptimiseRequest& request, const OptimiseOutcome& outcome) {
    const posegraph::OptimisationResult& r = outcome.result;
    std::ofstream out(file);
    out << "# Pose-graph optimisation\n\n"
        << "- dataset: `" << dataset.root().string() << "`, " << dataset.size() << " scans\n"
        << "- odometry: `" << OdometryName(request.odometry_file, request.odometry_topic, dataset)
        << "`\n"
        << "- loops: " << outcome.loops.size() << " accepted ("
        << (request.loops_file.empty() ? "detected with verification, detection/"
                                       : "`" + request.loops_file.string() + "`")
        << "); the back end used " << r.loops_used << ", rejected " << r.rejected_by_odometry
        << " against the odometry, " << r.rejected_by_consistency
        << " without support from neighbouring loops and " << r.rejected_by_residual
        << " by their residual\n";
    if (!outcome.loop_is_true.empty()) {
        out << "- against the ground truth: " << CountTrue(outcome, false) << " of the "
            << outcome.loops.size() << " loops are true (within "
            << Rounded(request.true_loop_translation_m) << " m and "
            << Rounded(request.true_loop_rotation_deg) << " deg); " << CountTrue(outcome, true)
            << " of the " << r.loops_used << " used are\n";
    }
    out << "- solver: " << r.solves << " Ceres solves, " << r.iterations << " iterations, "
        << Rounded(r.seconds, 3) << " s" << (r.converged ? "" : " (iteration limit reached)")
        << "\n";
    for (const std::string& note : outcome.notes) out << "- note: " << note << "\n";
    if (outcome.odometry && outcome.optimised) {
        const TrajectoryMetrics& a = *outcome.odometry;
        const TrajectoryMetrics& b = *outcome.optimised;
        out << "\n| trajectory | ATE RMSE (m) | RPE translation (%) | RPE rotation (deg/100 m) |\n"
            << "|---|---|---|---|\n"
            << "| odometry | " << Rounded(a.ate_rmse_m) << " | "
            << Rounded(a.rpe.translation_percent) << " | " << Rounded(a.rpe.rotation_deg_per_100m)
            << " |\n"
            << "| optimised | " << Rounded(b.ate_rmse_m) << " | "
            << Rounded(b.rpe.translation_percent) << " | " << Rounded(b.rpe.rotation_deg_per_100m)
            << " |\n\n"
            << "ATE: RMSE of positions after the best rigid alignment (Umeyama without scale). "
            << "RPE: KITTI's segments of 100..800 m from every 10th scan (" << b.rpe.segments
            << " segments).\n";
    }
    if (std::filesystem::exists(file.parent_path() / "trajectory.png")) {
        out << "\n![top view](trajectory.png)\n";
    }
    const MapSummary& maps = outcome.maps;
    out << "\n## Maps\n\nEvery scan placed with the odometry (left; a revisit the odometry "
           "drifted through shows doubled walls) and with the optimised poses (right), top view, "
           "coloured by scan time: `map_odometry.ply` ("
        << maps.odometry_points << " points) and `map_optimised.ply` (" << maps.optimised_points
        << " points), voxels of " << Rounded(maps.voxel_m, 3) << " m.\n\n![maps](map.png)\n";
    if (!out) throw io::WriteError(file, "writing failed");
}

}  // namespace lidarloop::app

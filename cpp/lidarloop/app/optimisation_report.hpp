#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarloop/app/optimisation.hpp"

namespace lidarloop::app {

/// loop_verdicts.csv: query,match,verdict,true,path_m,odometry_translation_error_m,
/// odometry_rotation_error_deg,gate_translation_m,gate_rotation_deg,initial_whitened_residual,
/// whitened_residual (docs/cli.md#loop_verdictscsv).
void WriteLoopVerdicts(const std::filesystem::path& file, const OptimiseOutcome& outcome);

/// The top view of the trajectories (x, y in metres): ground truth (when given), odometry and
/// optimised, the accepted loops drawn on the odometry from match to query (true and false in
/// two colours when judged), the loops the back end rejected marked. A note instead when gnuplot
/// is missing.
std::optional<std::string> DrawTrajectoryPlot(const std::filesystem::path& png,
                                              const std::vector<core::Transform>& odometry,
                                              const std::vector<core::Transform>& truth,
                                              const OptimiseOutcome& outcome);

/// metrics.json of `lidarloop optimise` (docs/cli.md#metricsjson-of-optimise).
nlohmann::json OptimisationMetricsJson(const io::Dataset& dataset, const OptimiseRequest& request,
                                       const OptimiseOutcome& outcome);

/// report.md of `lidarloop optimise`.
void WriteOptimisationReport(const std::filesystem::path& file, const io::Dataset& dataset,
                             const OptimiseRequest& request, const OptimiseOutcome& outcome);

}  // namespace lidarloop::app

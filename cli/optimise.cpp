#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "dataset_options.hpp"
#include "descriptor_options.hpp"
#include "lidarloop/app/optimisation.hpp"
#include "lidarloop/core/error.hpp"
#include "odometry_options.hpp"
#include "progress.hpp"
#include "run_options.hpp"
#include "run_output.hpp"

namespace lidarloop::cli {
namespace {

struct OptimiseFlags {
    DatasetOptions dataset;
    DescriptorOptions descriptor;
    RunOptionFlags options;  // app/run_options.hpp: detection keys, --max-odometry-step, ...
    OdometryOptions odometry;
    std::string loops;
    std::string out;
    std::string format = "kitti";
    bool overwrite = false;
    bool quiet = false;
};

std::string Figure(double value, const char* format) {
    char text[64];
    std::snprintf(text, sizeof(text), format, value);
    return text;
}

// KITTI's RPE averages segments of 100 m and more; a shorter path has none.
std::string RpeText(const app::TrajectoryMetrics& before, const app::TrajectoryMetrics& after) {
    if (before.rpe.segments == 0 || after.rpe.segments == 0) return "n/a (path shorter than 100 m)";
    return Figure(before.rpe.translation_percent, "%.2f") + " % -> " +
           Figure(after.rpe.translation_percent, "%.2f") + " %";
}

void PrintOutcome(const app::OptimiseRequest& request, const app::OptimiseOutcome& outcome) {
    const posegraph::OptimisationResult& r = outcome.result;
    std::set<std::size_t> scans_with_loops;
    for (const posegraph::LoopConstraint& loop : outcome.loops) scans_with_loops.insert(loop.query);
    std::cout << "lidarloop optimise: " << outcome.loops.size() << " accepted loops of "
              << scans_with_loops.size() << " scans, " << r.loops_used << " used, "
              << r.rejected_by_odometry << " rejected against the odometry, "
              << r.rejected_by_consistency << " without support, " << r.rejected_by_residual
              << " by their residual (" << r.solves << " solves, " << Figure(r.seconds, "%.2f")
              << " s)\n";
    if (outcome.odometry && outcome.optimised) {
        std::cout << "  ATE RMSE: odometry " << Figure(outcome.odometry->ate_rmse_m, "%.3f")
                  << " m -> optimised " << Figure(outcome.optimised->ate_rmse_m, "%.3f")
                  << " m; RPE " << RpeText(*outcome.odometry, *outcome.optimised) << "\n";
    }
    for (const std::string& note : outcome.notes) std::cout << "  note: " << note << "\n";
    std::cout << "  results in " << request.out.string()
              << "/ (poses_optimised.txt, graph.g2o, loop_verdicts.csv, metrics.json, report.md, "
                 "trajectory.png, map_odometry.ply, map_optimised.ply, map.png, config.yaml)\n";
}

std::vector<std::filesystem::path> Inputs(const OptimiseFlags& flags) {
    std::vector<std::filesystem::path> inputs = flags.dataset.Inputs();
    for (const auto& input : flags.odometry.Inputs()) inputs.push_back(input);
    inputs.emplace_back(flags.loops);
    inputs.emplace_back(flags.descriptor.config_file());
    return inputs;
}

void RunOptimise(const OptimiseFlags& flags) {
    if (!flags.odometry.given()) {
        throw core::ConfigError(
            "optimise needs the odometry: give --odometry FILE, or --odometry-topic TOPIC for a "
            "bag");
    }
    ProgressPrinter progress(flags.quiet);
    app::OptimiseRequest request;
    request.config = flags.descriptor.Resolve();
    flags.options.ApplyTo({&request.config, &request.skip_bad});
    request.odometry_file = flags.odometry.file();
    request.odometry_topic = flags.odometry.topic();
    request.odometry_calib = flags.odometry.calib();
    request.loops_file = flags.loops;
    request.format = flags.format == "tum" ? app::PoseFormat::kTum : app::PoseFormat::kKitti;
    request.progress = progress.Callback();
    request.out = flags.out;
    const io::Dataset dataset = flags.dataset.Open();
    const app::OptimiseOutcome outcome =
        RunInFolder(flags.out, Inputs(flags), flags.overwrite, [&](const auto& staging) {
            app::OptimiseRequest staged = request;
            staged.out = staging;
            return app::RunOptimisation(dataset, staged);
        });
    PrintOutcome(request, outcome);
}

}  // namespace

void AddOptimiseCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "optimise", "Optimise the odometry with the accepted loops in a pose graph (Ceres)");
    auto flags = std::make_shared<OptimiseFlags>();
    flags->dataset.AddTo(*command, "--dataset-format");
    flags->odometry.AddTo(*command, "the pose graph's odometry edges and initial estimate");
    command
        ->add_option("--loops", flags->loops,
                     "loops.csv of `detect` (with verification); default: detect them first")
        ->check(CLI::ExistingFile);
    command->add_option("--out", flags->out, "folder for the results (created)")->required();
    command->add_option("--format", flags->format, "poses_optimised.txt format: kitti | tum")
        ->check(CLI::IsMember({"kitti", "tum"}))
        ->capture_default_str();
    flags->descriptor.AddTo(*command);
    flags->options.AddTo(*command, app::RunCommand::kOptimise);
    command->add_flag("--overwrite", flags->overwrite,
                      "write into a non-empty folder that holds no lidarloop run.json");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunOptimise(*flags); });
}

}  // namespace lidarloop::cli

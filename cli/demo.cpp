#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <utility>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/app/optimisation.hpp"
#include "lidarloop/app/simulation.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/pipeline/scancontext_method.hpp"
#include "progress.hpp"
#include "retrieval_print.hpp"
#include "run_output.hpp"

namespace lidarloop::cli {
namespace {

struct DemoFlags {
    std::string out = "lidarloop_demo";
    bool overwrite = false;
    bool quiet = false;
};

std::string Fixed(double value, int decimals) {
    char text[64];
    std::snprintf(text, sizeof(text), "%.*f", decimals, value);
    return text;
}

void PrintSequence(const app::DemoSequence& demo, std::size_t scans) {
    if (!demo.generated) return;
    std::cout << "demo sequence: " << scans << " synthetic VLP-16 scans of a town "
              << "(grid route with same-lane, opposite-direction and lane-offset revisits), "
              << demo.generated->revisited_scans << " of them revisit a place, generated in "
              << Fixed(demo.generated->seconds, 2) << " s -> " << demo.folder.string() << "\n";
}

void PrintMethod(const app::MethodEvaluation& e) {
    const double threshold = *e.default_threshold;
    const eval::TaxonomyCounts& at_default = *e.per_scan_at_default;
    const std::size_t found =
        at_default.true_positive + at_default.mismatch + at_default.false_positive;
    std::cout << "  " << e.name << ": " << found << " scans matched at the default threshold "
              << threshold << " (" << at_default.true_positive << " correct, "
              << at_default.mismatch << " mismatched, " << at_default.false_positive
              << " false); all pairs: best F1 " << Fixed(e.pairwise.best_f1.score, 3)
              << ", best MCC " << Fixed(e.pairwise.best_mcc.score, 3) << " (tau "
              << e.pairwise.best_mcc.threshold << ")";
    if (e.learnt) {
        std::cout << ", learnt on the first half -> test MCC " << Fixed(e.learnt->test_mcc, 3);
    }
    std::cout << "; recall at zero errors " << Fixed(100.0 * e.per_scan.zero_error.recall, 1)
              << " %\n";
    // The online detector on the same scans: the descriptor's threshold against verification.
    if (e.retrieval) PrintRetrieval(*e.retrieval);
}

// A results folder of the demo (evaluation, optimised) with the guarantees of every results
// folder: it replaces what an earlier demo left there, and nothing else without --overwrite.
template <typename Run>
auto RunDemoStage(const std::filesystem::path& out, const io::Dataset& dataset, bool overwrite,
                  Run&& run) {
    return RunInFolder(out, {dataset.root()}, overwrite, std::forward<Run>(run));
}

// The loops closed: detect with verification, then the pose graph on the simulated odometry.
void RunDemoOptimisation(const io::Dataset& dataset, const DemoFlags& flags,
                         ProgressPrinter& progress) {
    const std::filesystem::path out(flags.out);
    app::OptimiseRequest request;
    request.odometry_file = dataset.root() / "poses_odometry.txt";
    request.progress = progress.Callback();
    request.out = out / "optimised";
    const app::OptimiseOutcome outcome =
        RunDemoStage(request.out, dataset, flags.overwrite, [&](const auto& staging) {
            app::OptimiseRequest staged = request;
            staged.out = staging;
            return app::RunOptimisation(dataset, staged);
        });
    std::cout << "loops closed: " << outcome.result.loops_used << " of " << outcome.loops.size()
              << " verified loops in the pose graph; ATE " << Fixed(outcome.odometry->ate_rmse_m, 2)
              << " m (odometry) -> " << Fixed(outcome.optimised->ate_rmse_m, 2)
              << " m (optimised); top view: " << (request.out / "trajectory.png").string()
              << ", maps before and after: " << (request.out / "map.png").string() << "\n";
}

void RunDemo(const DemoFlags& flags) {
    const std::filesystem::path out(flags.out);
    ProgressPrinter progress(flags.quiet);
    // The results folders are checked before the sequence is simulated, not refused after it.
    for (const char* stage : {"evaluation", "optimised"})
        app::CheckRunFolder(out / stage, CommandRun({out / "sequence"}, flags.overwrite));
    const app::DemoSequence demo = app::PrepareDemoSequence(
        out / "sequence", CommandRun({}, flags.overwrite), progress.Callback());
    const io::Dataset dataset = io::OpenDataset(demo.folder);
    PrintSequence(demo, dataset.size());
    app::EvaluationRequest request;
    request.methods = {core::Method::kHeight, core::Method::kRange, core::Method::kNdt,
                       pipeline::ScanContextMethod::kMethod};
    request.distance_m = 10.0;  // Röhling's d
    request.progress = progress.Callback();
    request.out = out / "evaluation";
    const app::EvaluationOutcome outcome =
        RunDemoStage(request.out, dataset, flags.overwrite, [&](const auto& staging) {
            app::EvaluationRequest staged = request;
            staged.out = staging;
            return app::RunEvaluation(dataset, staged);
        });
    std::cout << "ground truth: " << outcome.truth.Describe() << "\n";
    for (const app::MethodEvaluation& e : outcome.methods) PrintMethod(e);
    // The demo evaluates the scans alone on purpose and gives the odometry to the pose graph:
    // the note that its poses_odometry.txt is not read would mislead here.
    const std::string unused_odometry = app::UnusedOdometryNote(dataset, {}, true);
    for (const std::string& note : outcome.notes) {
        if (note != unused_odometry) std::cout << "  note: " << note << "\n";
    }
    std::cout << "figures and tables: " << (request.out / "report.md").string()
              << " (similarity matrices, ROC, precision-recall, EM fit, counts against t_d)\n";
    RunDemoOptimisation(dataset, flags, progress);
}

}  // namespace

void AddDemoCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "demo", "Simulate the bundled demo sequence and evaluate every method on it");
    auto flags = std::make_shared<DemoFlags>();
    command->add_option("--out", flags->out, "folder for the sequence and the results")
        ->capture_default_str();
    command->add_flag("--overwrite", flags->overwrite,
                      "write into folders (sequence, evaluation, optimised) that hold no "
                      "lidarloop run.json, replacing their files of the same names");
    command->add_flag("--quiet", flags->quiet, "no progress bars");
    command->callback([flags] { RunDemo(*flags); });
}

}  // namespace lidarloop::cli

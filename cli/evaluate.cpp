#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "dataset_options.hpp"
#include "descriptor_options.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"
#include "odometry_options.hpp"
#include "progress.hpp"
#include "retrieval_print.hpp"
#include "run_options.hpp"
#include "run_output.hpp"

namespace lidarloop::cli {
namespace {

struct EvaluateFlags {
    DatasetOptions dataset;
    DescriptorOptions descriptor;
    RunOptionFlags options;  // app/run_options.hpp: the ground truth, learning, detection keys
    std::vector<std::string> methods = pipeline::MethodNames();
    std::vector<std::string> results;
    OdometryOptions odometry;  // submaps and the odometry gate in verification
    std::string train_on;
    std::string train_poses;
    std::string out;
    bool overwrite = false;
    bool quiet = false;
};

// CLI11 names the flag in the message of a failed check.
CLI::Validator RegisteredMethod() {
    return CLI::Validator(
        [](const std::string& name) {
            try {
                pipeline::ParseMethod(name);
                return std::string();
            } catch (const core::ConfigError& e) {
                return std::string(e.what());
            }
        },
        "METHOD");
}

// --min and --max set the value range of the one histogram method evaluated; with both (or
// neither) it is not clear which range they mean.
io::RunConfig ResolveConfig(const EvaluateFlags& flags, const std::vector<core::Method>& methods) {
    io::RunConfig base;
    if (flags.descriptor.GivesValueRange()) {
        std::vector<core::Method> histograms;
        for (const core::Method& m : methods) {
            if (core::IsHistogramMethod(m)) histograms.push_back(m);
        }
        if (histograms.size() != 1) {
            throw core::ConfigError(
                "--min and --max set the value range of one histogram method: evaluate only "
                "height or only range with them, or set histogram.height_min_m / range_min_m "
                "(and _max_m) in --config");
        }
        base.descriptor.method = histograms.front();
    }
    return flags.descriptor.Resolve(base);
}

app::EvaluationRequest RequestOf(const EvaluateFlags& flags) {
    app::EvaluationRequest request;
    for (const std::string& name : flags.methods)
        request.methods.push_back(pipeline::ParseMethod(name));
    request.config = ResolveConfig(flags, request.methods);
    flags.options.ApplyTo({&request.config, &request.skip_bad, &request});
    request.results_files = flags.results;
    request.odometry_file = flags.odometry.file();
    request.odometry_topic = flags.odometry.topic();
    request.odometry_calib = flags.odometry.calib();
    request.out = flags.out;
    return request;
}

std::optional<io::Dataset> TrainingDataset(const EvaluateFlags& flags) {
    if (flags.train_on.empty()) {
        if (!flags.train_poses.empty())
            throw core::ConfigError("--train-poses needs --train-on DATASET");
        return std::nullopt;
    }
    io::DatasetOptions options;
    options.poses_file = flags.train_poses;
    return io::OpenDataset(flags.train_on, options);
}

void PrintOutcome(const io::Dataset& dataset, const app::EvaluationOutcome& outcome,
                  const std::filesystem::path& out) {
    std::cout << "lidarloop evaluate: " << dataset.size() << " scans, " << outcome.truth.Describe()
              << "\n";
    for (const app::MethodEvaluation& e : outcome.methods) {
        std::cout << "  " << e.name << ": best MCC " << e.pairwise.best_mcc.score << " (tau "
                  << e.pairwise.best_mcc.threshold << "), best F1 " << e.pairwise.best_f1.score
                  << ", recall at zero errors " << 100.0 * e.per_scan.zero_error.recall << " %\n";
        if (e.retrieval) PrintRetrieval(*e.retrieval);
    }
    for (const std::string& note : outcome.notes) std::cout << "  note: " << note << "\n";
    std::cout << "  report: " << (out / "report.md").string() << "\n";
}

std::vector<std::filesystem::path> Inputs(const EvaluateFlags& flags) {
    std::vector<std::filesystem::path> inputs = flags.dataset.Inputs();
    inputs.insert(inputs.end(), flags.results.begin(), flags.results.end());
    inputs.emplace_back(flags.train_on);
    inputs.emplace_back(flags.train_poses);
    inputs.emplace_back(flags.descriptor.config_file());
    for (const auto& input : flags.odometry.Inputs()) inputs.push_back(input);
    return inputs;
}

void RunEvaluate(const EvaluateFlags& flags) {
    ProgressPrinter progress(flags.quiet);
    app::EvaluationRequest request = RequestOf(flags);
    request.progress = progress.Callback();
    const io::Dataset dataset = flags.dataset.Open();
    const std::optional<io::Dataset> train_dataset = TrainingDataset(flags);
    const app::EvaluationOutcome outcome = RunInFolder(
        flags.out, Inputs(flags), flags.overwrite, [&](const std::filesystem::path& staging) {
            app::EvaluationRequest staged = request;
            staged.out = staging;
            return app::RunEvaluation(dataset, staged, train_dataset ? &*train_dataset : nullptr);
        });
    PrintOutcome(dataset, outcome, request.out);
}

void AddTrainingFlags(CLI::App& command, EvaluateFlags& flags) {
    command
        .add_option("--train-on", flags.train_on,
                    "learn each method's threshold on all pairs of this dataset (same rule) "
                    "instead of the first part")
        ->check(CLI::ExistingDirectory);
    command.add_option("--train-poses", flags.train_poses, "poses file of --train-on")
        ->check(CLI::ExistingFile);
}

}  // namespace

void AddEvaluateCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "evaluate", "Score loop detection against ground-truth poses, as both papers do");
    auto flags = std::make_shared<EvaluateFlags>();
    flags->dataset.AddTo(*command);
    flags->descriptor.AddTo(*command, /*with_method=*/false);
    command
        ->add_option("--method", flags->methods,
                     "methods to evaluate on the same ground truth (repeatable; default all)")
        ->check(RegisteredMethod());
    command
        ->add_option("--results", flags->results,
                     "also score another detector's CSV (query,match,distance); repeatable")
        ->check(CLI::ExistingFile);
    flags->options.AddTo(*command, app::RunCommand::kEvaluate);
    AddTrainingFlags(*command, *flags);
    flags->odometry.AddTo(*command,
                          "verification registers submaps placed by it and rejects loops it "
                          "contradicts, as detect --odometry (never the ground truth; without "
                          "it each scan's registration to the one before places the submaps; "
                          "dense scans are verified alone)");
    command->add_option("--out", flags->out, "folder for the results (created)")->required();
    command->add_flag("--overwrite", flags->overwrite,
                      "write into a non-empty folder that holds no earlier lidarloop run");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunEvaluate(*flags); });
}

}  // namespace lidarloop::cli

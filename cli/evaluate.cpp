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
#include "detection_options.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"
#include "progress.hpp"
#include "retrieval_print.hpp"
#include "run_output.hpp"

namespace lidarloop::cli {
namespace {

struct EvaluateFlags {
    DatasetOptions dataset;
    DescriptorOptions descriptor;
    DetectionOptions detection;
    std::vector<std::string> methods = pipeline::MethodNames();
    std::vector<std::string> results;
    double distance_m = 10.0;
    double max_heading_deg = 0.0;
    double min_path_m = 0.0;
    double train_fraction = 0.5;
    std::string criterion = "mcc";
    std::vector<double> fixed_thresholds;
    std::string train_on;
    std::string train_poses;
    std::string out;
    bool skip_bad = false;
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
    io::RunConfig config = flags.descriptor.Resolve(base);
    flags.detection.ApplyTo(config);
    return config;
}

app::EvaluationRequest RequestOf(const EvaluateFlags& flags) {
    app::EvaluationRequest request;
    for (const std::string& name : flags.methods)
        request.methods.push_back(pipeline::ParseMethod(name));
    request.config = ResolveConfig(flags, request.methods);
    request.results_files = flags.results;
    request.distance_m = flags.distance_m;
    request.max_heading_deg = flags.max_heading_deg;
    request.min_path_m = flags.min_path_m;
    request.learning.train_fraction = flags.train_fraction;
    request.learning.criterion = eval::ParseCriterion(flags.criterion);
    request.fixed_thresholds = flags.fixed_thresholds;
    request.skip_bad = flags.skip_bad;
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

void AddGroundTruthFlags(CLI::App& command, EvaluateFlags& flags) {
    command.add_option("--distance", flags.distance_m,
                       "same place when closer than this, metres (Roehling 10, Magnusson 3-10)");
    command.add_option("--max-heading", flags.max_heading_deg,
                       "and headings differ by less than this, degrees (0: any; Kvarntorp 20)");
    command.add_option("--min-path", flags.min_path_m,
                       "pairs not more than this much path apart (metres on the poses) are not "
                       "evaluated, besides the gap (0: no path rule; SLAM revisits: 50)");
    flags.detection.AddTo(command, /*decides_loops=*/true,
                          "S: pairs closer in the sequence are not evaluated");
}

void AddLearningFlags(CLI::App& command, EvaluateFlags& flags) {
    command.add_option("--train-fraction", flags.train_fraction,
                       "share of the sequence a threshold is learnt on (default 0.5)");
    command
        .add_option("--train-on", flags.train_on,
                    "learn each method's threshold on all pairs of this dataset (same rule) "
                    "instead of the first part")
        ->check(CLI::ExistingDirectory);
    command.add_option("--train-poses", flags.train_poses, "poses file of --train-on")
        ->check(CLI::ExistingFile);
    command.add_option("--criterion", flags.criterion,
                       "what the learnt threshold maximises: mcc | f1");
    command
        .add_option("--fixed-thresholds", flags.fixed_thresholds,
                    "also report MCC and F1 at these thresholds (Roehling table II)")
        ->delimiter(',');
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
    AddGroundTruthFlags(*command, *flags);
    AddLearningFlags(*command, *flags);
    command->add_option("--out", flags->out, "folder for the results (created)")->required();
    command->add_flag("--skip-bad", flags->skip_bad, "skip unreadable scans instead of stopping");
    command->add_flag("--overwrite", flags->overwrite,
                      "write into a non-empty folder that holds no earlier lidarloop run");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunEvaluate(*flags); });
}

}  // namespace lidarloop::cli

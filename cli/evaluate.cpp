#include <algorithm>
#include <iostream>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dataset_options.hpp"
#include "descriptor_options.hpp"
#include "evaluate.hpp"
#include "evaluation_report.hpp"
#include "evaluation_run.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/results_csv.hpp"
#include "run_output.hpp"

namespace lidarloop::cli {
namespace {

struct EvaluateFlags {
    DatasetOptions dataset;
    DescriptorOptions descriptor;
    std::vector<std::string> methods;
    std::vector<std::string> results;
    double distance_m = 10.0;
    double max_heading_deg = 0.0;
    double min_gap = 0.0;
    std::string min_gap_unit;
    CLI::Option* min_gap_option = nullptr;
    double train_fraction = 0.5;
    std::string criterion = "mcc";
    std::vector<double> fixed_thresholds;
    std::string train_on;
    std::string train_poses;
    std::string out;
    bool skip_bad = false;
    bool quiet = false;
};

eval::GroundTruthConfig GroundTruthRule(const EvaluationRequest& request) {
    eval::GroundTruthConfig rule;
    rule.distance_m = request.distance_m;
    rule.max_heading_deg = request.max_heading_deg;
    rule.min_gap = request.config.detection.min_gap;
    rule.Validate();
    return rule;
}

// The similarity matrix of an external detector: listed pairs get their distance (the smallest
// when listed twice), every other pair +inf (never detected).
pipeline::SimilarityMatrix MatrixOfResults(const std::string& file, std::size_t scans) {
    pipeline::SimilarityMatrix matrix(scans);
    std::fill(matrix.condensed().begin(), matrix.condensed().end(),
              std::numeric_limits<float>::infinity());
    for (const io::ExternalResult& r : io::ReadResultsCsv(file)) {
        if (r.query >= scans || r.match >= scans) {
            throw io::ReadError(file, "pair (" + std::to_string(r.query) + ", " +
                                          std::to_string(r.match) + ") names a scan beyond the " +
                                          std::to_string(scans) + " of the dataset");
        }
        if (r.query == r.match) continue;
        const std::size_t i = std::min(r.query, r.match);
        const std::size_t j = std::max(r.query, r.match);
        matrix.set(i, j, std::min(matrix.at(i, j), static_cast<float>(r.distance)));
    }
    return matrix;
}

// `poses_flag` names the option that gives a dataset its poses.
void RequirePoses(const io::Dataset& dataset, const std::string& role,
                  const std::string& poses_flag) {
    if (!dataset.HasPoses()) {
        throw core::ConfigError(dataset.root().string() + " has no poses; " + role +
                                " needs ground truth (" + poses_flag + " FILE)");
    }
}

// Every scored pair of the training dataset under the evaluation's ground-truth rule.
TrainingPairs TrainingPairsOf(const EvaluationRequest& request,
                              const core::DescriptorConfig& descriptor,
                              const io::Dataset& train_dataset) {
    const auto described =
        DescribeDataset(train_dataset, descriptor,
                        {"training set (" + core::ToString(descriptor.method) + ")",
                         request.skip_bad, request.quiet});
    const pipeline::SimilarityMatrix matrix = pipeline::ComputeSimilarityMatrix(described.database);
    const eval::GroundTruth truth =
        eval::BuildGroundTruth(train_dataset.poses(), GroundTruthRule(request));
    return {"all pairs of " + train_dataset.root().string(),
            eval::CollectPairs(matrix.condensed(), truth)};
}

MethodEvaluation EvaluateMethod(const EvaluationRequest& request, core::Method method,
                                const io::Dataset& dataset, const eval::GroundTruth& truth,
                                const io::Dataset* train_dataset) {
    io::RunConfig config = request.config;
    config.descriptor.method = method;
    std::optional<TrainingPairs> training;
    if (train_dataset != nullptr)
        training = TrainingPairsOf(request, config.descriptor, *train_dataset);
    const auto described = DescribeDataset(
        dataset, config.descriptor,
        {"describing (" + core::ToString(method) + ")", request.skip_bad, request.quiet});
    Stopwatch matrix_clock;
    pipeline::SimilarityMatrix matrix = pipeline::ComputeSimilarityMatrix(described.database);
    const double matrix_s = matrix_clock.Seconds();
    const double pairs = static_cast<double>(matrix.condensed().size());
    MethodEvaluation e = EvaluateMatrix(core::ToString(method), std::move(matrix), truth,
                                        request.learning, core::DefaultThreshold(config.descriptor),
                                        request.fixed_thresholds, training ? &*training : nullptr);
    e.describe_ms_per_scan_median = 1e3 * Quantile(described.describe_seconds, 0.5);
    e.ns_per_comparison = pairs > 0 ? 1e9 * matrix_s / pairs : 0.0;
    return e;
}

void RunEvaluate(const EvaluateFlags& flags) {
    EvaluationRequest request;
    request.config = flags.descriptor.Resolve();
    if (*flags.min_gap_option) request.config.detection.min_gap.value = flags.min_gap;
    if (!flags.min_gap_unit.empty()) {
        request.config.detection.min_gap.unit = core::ParseMinGapUnit(flags.min_gap_unit);
    }
    request.config.Validate();
    for (const std::string& name : flags.methods)
        request.methods.push_back(core::ParseMethod(name));
    request.results_files = flags.results;
    request.distance_m = flags.distance_m;
    request.max_heading_deg = flags.max_heading_deg;
    request.learning.train_fraction = flags.train_fraction;
    request.learning.criterion = eval::ParseCriterion(flags.criterion);
    request.fixed_thresholds = flags.fixed_thresholds;
    request.skip_bad = flags.skip_bad;
    request.quiet = flags.quiet;
    request.out = flags.out;
    const io::Dataset dataset = flags.dataset.Open();
    std::optional<io::Dataset> train_dataset;
    if (!flags.train_on.empty()) {
        io::DatasetOptions options;
        options.poses_file = flags.train_poses;
        train_dataset = io::OpenDataset(flags.train_on, options);
    } else if (!flags.train_poses.empty()) {
        throw core::ConfigError("--train-poses needs --train-on DATASET");
    }
    const EvaluationOutcome outcome =
        RunEvaluation(dataset, request, train_dataset ? &*train_dataset : nullptr);
    std::cout << "lidarloop evaluate: " << dataset.size() << " scans, " << outcome.truth.Describe()
              << "\n";
    for (const MethodEvaluation& e : outcome.methods) {
        std::cout << "  " << e.name << ": best MCC " << e.pairwise.best_mcc.score << " (tau "
                  << e.pairwise.best_mcc.threshold << "), best F1 " << e.pairwise.best_f1.score
                  << ", recall at zero errors " << 100.0 * e.per_scan.zero_error.recall << " %\n";
    }
    for (const std::string& note : outcome.notes) std::cout << "  note: " << note << "\n";
    std::cout << "  report: " << (request.out / "report.md").string() << "\n";
}

}  // namespace

EvaluationOutcome RunEvaluation(const io::Dataset& dataset, const EvaluationRequest& request,
                                const io::Dataset* train_dataset) {
    request.learning.Validate();
    RequirePoses(dataset, "evaluation", "--poses");
    if (train_dataset != nullptr)
        RequirePoses(*train_dataset, "threshold learning", "--train-poses");
    EvaluationOutcome outcome{
        eval::BuildGroundTruth(dataset.poses(), GroundTruthRule(request)), {}, {}};
    const eval::GroundTruth& truth = outcome.truth;
    const std::filesystem::path out_dir = PrepareOutputFolder(request.out.string());
    io::WriteConfigYaml(out_dir / "config.yaml", request.config);
    for (core::Method method : request.methods) {
        outcome.methods.push_back(EvaluateMethod(request, method, dataset, truth, train_dataset));
    }
    for (const std::string& file : request.results_files) {
        outcome.methods.push_back(
            EvaluateMatrix("results:" + std::filesystem::path(file).stem().string(),
                           MatrixOfResults(file, dataset.size()), truth, request.learning,
                           std::nullopt, request.fixed_thresholds));
    }
    nlohmann::json metrics;
    metrics["dataset"] = dataset.root().string();
    metrics["scans"] = dataset.size();
    metrics["ground_truth"] = {{"rule", truth.Describe()},
                               {"distance_m", truth.config.distance_m},
                               {"max_heading_deg", truth.config.max_heading_deg},
                               {"min_gap", truth.config.min_gap.value},
                               {"min_gap_unit", core::ToString(truth.config.min_gap.unit)}};
    for (const MethodEvaluation& e : outcome.methods) metrics["methods"][e.name] = MetricsJson(e);
    WriteJson(out_dir / "metrics.json", metrics);
    WriteCurveCsvs(out_dir, outcome.methods);
    outcome.notes = WriteFigures(out_dir, truth, outcome.methods);
    WriteReport(out_dir, {dataset.root().string(), dataset.size(), truth.Describe()},
                outcome.methods, outcome.notes);
    return outcome;
}

void AddEvaluateCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "evaluate", "Score loop detection against ground-truth poses, as both papers do");
    auto flags = std::make_shared<EvaluateFlags>();
    flags->dataset.AddTo(*command);
    flags->descriptor.AddTo(*command, /*with_method=*/false);
    flags->methods = {"height", "range", "ndt"};
    command
        ->add_option("--method", flags->methods,
                     "methods to evaluate on the same ground truth (repeatable; default all)")
        ->check(CLI::IsMember({"height", "range", "ndt"}));
    command
        ->add_option("--results", flags->results,
                     "also score another detector's CSV (query,match,distance); repeatable")
        ->check(CLI::ExistingFile);
    command->add_option("--distance", flags->distance_m,
                        "same place when closer than this, metres (Roehling 10, Magnusson 3-10)");
    command->add_option("--max-heading", flags->max_heading_deg,
                        "and headings differ by less than this, degrees (0: any; Kvarntorp 20)");
    flags->min_gap_option = command->add_option(
        "--min-gap", flags->min_gap, "S: pairs closer in the sequence are not evaluated");
    command->add_option("--min-gap-unit", flags->min_gap_unit,
                        "unit of --min-gap: scans | seconds");
    command->add_option("--train-fraction", flags->train_fraction,
                        "share of the sequence a threshold is learnt on (default 0.5)");
    command
        ->add_option("--train-on", flags->train_on,
                     "learn each method's threshold on all pairs of this dataset (same rule) "
                     "instead of the first part")
        ->check(CLI::ExistingDirectory);
    command->add_option("--train-poses", flags->train_poses, "poses file of --train-on")
        ->check(CLI::ExistingFile);
    command->add_option("--criterion", flags->criterion,
                        "what the learnt threshold maximises: mcc | f1");
    command
        ->add_option("--fixed-thresholds", flags->fixed_thresholds,
                     "also report MCC and F1 at these thresholds (Roehling table II)")
        ->delimiter(',');
    command->add_option("--out", flags->out, "folder for the results (created)")->required();
    command->add_flag("--skip-bad", flags->skip_bad, "skip unreadable scans instead of stopping");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunEvaluate(*flags); });
}

}  // namespace lidarloop::cli

#include "lidarloop/app/evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/app/evaluation_report.hpp"
#include "lidarloop/app/metrics_json.hpp"
#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/results_csv.hpp"

namespace lidarloop::app {
namespace {

void LearnThreshold(MethodEvaluation& e, const std::vector<eval::ScoredPair>& pairs,
                    std::size_t scans, const eval::ThresholdLearningConfig& learning,
                    const TrainingPairs* training) {
    try {
        if (training != nullptr) {
            e.learnt = eval::LearnAndTest(training->pairs, pairs, learning.criterion);
            e.learnt_on = training->source;
        } else {
            e.learnt = eval::LearnOnFirstPart(pairs, scans, learning);
            e.learnt_on = "the queries of the first " +
                          std::to_string(std::lround(100.0 * learning.train_fraction)) +
                          " % of the scans";
        }
    } catch (const core::EmptyInputError&) {
        // Too short a sequence to split, or no pairs: the learnt row is left out of the report.
    }
}

void EvaluatePerScan(MethodEvaluation& e, const eval::GroundTruth& truth) {
    e.best_matches = eval::BestMatchesFromCondensed(e.matrix.condensed(), truth);
    e.per_scan = eval::EvaluatePerScan(e.best_matches, truth);
    for (const eval::BestMatch& m : e.best_matches) e.smallest_differences.push_back(m.distance);
    e.em = eval::EstimateDifferenceThreshold(e.smallest_differences);
    e.distinctiveness = eval::SummarizeDistinctiveness(e.best_matches);
}

// A pair of a results file must name scans of the dataset, and a finite distance must stay
// finite in the float matrix: overflowing to +inf would silently make it "never detected".
void CheckResult(const std::filesystem::path& file, const io::ExternalResult& r,
                 std::size_t scans) {
    const std::string pair =
        "pair (" + std::to_string(r.query) + ", " + std::to_string(r.match) + ")";
    if (r.query >= scans || r.match >= scans) {
        throw io::ReadError(
            file, pair + " names a scan beyond the " + std::to_string(scans) + " of the dataset");
    }
    if (std::isfinite(r.distance) && !std::isfinite(static_cast<float>(r.distance))) {
        throw io::ReadError(file, pair +
                                      ": the distance is beyond the float range (|d| > 3.4e38) "
                                      "the evaluation stores; scale the distances down");
    }
}

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
                         request.skip_bad,
                         pipeline::Execution::kParallel,
                         request.progress,
                         {}});
    const pipeline::SimilarityMatrix matrix = pipeline::ComputeSimilarityMatrix(described.database);
    const eval::GroundTruth truth =
        eval::BuildGroundTruth(train_dataset.poses(), GroundTruthRule(request));
    return {"all pairs of " + train_dataset.root().string(),
            eval::CollectPairs(matrix.condensed(), truth)};
}

// Scans prepared for verification once per evaluation: while the first method describes them.
struct VerificationState {
    std::optional<PreparedScans> prepared;
    bool collected = false;
    pipeline::VerificationCache cache;
};

MethodEvaluation EvaluateMethod(const EvaluationRequest& request, core::Method method,
                                const io::Dataset& dataset, const eval::GroundTruth& truth,
                                const io::Dataset* train_dataset, VerificationState& verification) {
    io::RunConfig config = request.config;
    config.descriptor.method = method;
    std::optional<TrainingPairs> training;
    if (train_dataset != nullptr)
        training = TrainingPairsOf(request, config.descriptor, *train_dataset);
    DescribeRun run{"describing (" + core::ToString(method) + ")",
                    request.skip_bad,
                    pipeline::Execution::kParallel,
                    request.progress,
                    {}};
    if (verification.prepared && !verification.collected) {
        run.with_cloud = verification.prepared->Collector(config.detection.verification.reduction);
        verification.collected = true;
    }
    const auto described = DescribeDataset(dataset, config.descriptor, run);
    Stopwatch matrix_clock;
    pipeline::SimilarityMatrix matrix = pipeline::ComputeSimilarityMatrix(described.database);
    const double matrix_s = matrix_clock.Seconds();
    const double pairs = static_cast<double>(matrix.condensed().size());
    MethodEvaluation e = EvaluateMatrix(core::ToString(method), std::move(matrix), truth,
                                        request.learning, config.detection.ThresholdFor(method),
                                        request.fixed_thresholds, training ? &*training : nullptr);
    e.describe_ms_per_scan_median = 1e3 * Quantile(described.describe_seconds, 0.5);
    e.ns_per_comparison = pairs > 0 ? 1e9 * matrix_s / pairs : 0.0;
    e.retrieval =
        CompareRetrieval(e.matrix, described.database.times_s(), config.detection, method, truth,
                         dataset.poses(), verification.prepared ? &*verification.prepared : nullptr,
                         &verification.cache, request.progress);
    return e;
}

void WriteEvaluationResults(const std::filesystem::path& out_dir, const io::Dataset& dataset,
                            EvaluationOutcome& outcome) {
    const eval::GroundTruth& truth = outcome.truth;
    WriteJson(out_dir / "metrics.json",
              EvaluationMetricsJson(dataset.root().string(), dataset.size(), outcome));
    WriteCurveCsvs(out_dir, outcome.methods);
    outcome.notes = WriteFigures(out_dir, truth, outcome.methods);
    WriteReport(out_dir, {dataset.root().string(), dataset.size(), truth.Describe()},
                outcome.methods, outcome.notes);
}

}  // namespace

MethodEvaluation EvaluateMatrix(std::string name, pipeline::SimilarityMatrix matrix,
                                const eval::GroundTruth& truth,
                                const eval::ThresholdLearningConfig& learning,
                                std::optional<double> default_threshold,
                                const std::vector<double>& fixed_thresholds,
                                const TrainingPairs* training) {
    MethodEvaluation e;
    e.name = std::move(name);
    e.default_threshold = default_threshold;
    e.matrix = std::move(matrix);
    const std::vector<eval::ScoredPair> pairs = eval::CollectPairs(e.matrix.condensed(), truth);
    e.pairwise = eval::EvaluatePairs(pairs);
    LearnThreshold(e, pairs, truth.size(), learning, training);
    if (default_threshold) e.at_default = eval::ConfusionAt(pairs, *default_threshold);
    e.fixed_thresholds = fixed_thresholds;
    e.at_fixed = eval::ConfusionsAt(pairs, fixed_thresholds);
    EvaluatePerScan(e, truth);
    if (default_threshold) {
        e.per_scan_at_default =
            eval::CountLabels(eval::LabelScans(e.best_matches, truth, *default_threshold));
    }
    return e;
}

pipeline::SimilarityMatrix MatrixOfResults(const std::filesystem::path& file, std::size_t scans) {
    // +inf: never detected (eval::ScoredPair), the rule for every pair the file leaves out.
    pipeline::SimilarityMatrix matrix(scans);
    std::fill(matrix.condensed().begin(), matrix.condensed().end(),
              std::numeric_limits<float>::infinity());
    for (const io::ExternalResult& r : io::ReadResultsCsv(file)) {
        CheckResult(file, r, scans);
        if (r.query == r.match) continue;
        const std::size_t i = std::min(r.query, r.match);
        const std::size_t j = std::max(r.query, r.match);
        matrix.set(i, j, std::min(matrix.at(i, j), static_cast<float>(r.distance)));
    }
    return matrix;
}

eval::GroundTruthConfig GroundTruthRule(const EvaluationRequest& request) {
    eval::GroundTruthConfig rule;
    rule.distance_m = request.distance_m;
    rule.max_heading_deg = request.max_heading_deg;
    rule.min_gap = request.config.detection.min_gap;
    rule.Validate();
    return rule;
}

EvaluationOutcome RunEvaluation(const io::Dataset& dataset, const EvaluationRequest& request,
                                const io::Dataset* train_dataset) {
    request.learning.Validate();
    if (request.config.detection.threshold && request.methods.size() > 1) {
        throw core::ConfigError(
            "detection.threshold (" + std::to_string(*request.config.detection.threshold) +
            ") is the threshold of one method; evaluate one method with it, or leave it default");
    }
    RequirePoses(dataset, "evaluation", "--poses");
    if (train_dataset != nullptr)
        RequirePoses(*train_dataset, "threshold learning", "--train-poses");
    EvaluationOutcome outcome{
        eval::BuildGroundTruth(dataset.poses(), GroundTruthRule(request)), {}, {}};
    const std::filesystem::path out_dir = PrepareOutputFolder(request.out);
    io::WriteConfigYaml(out_dir / "config.yaml", request.config);
    VerificationState verification;
    if (request.config.detection.verify) verification.prepared.emplace(dataset.size());
    for (core::Method method : request.methods) {
        outcome.methods.push_back(
            EvaluateMethod(request, method, dataset, outcome.truth, train_dataset, verification));
    }
    for (const std::string& file : request.results_files) {
        outcome.methods.push_back(
            EvaluateMatrix("results:" + std::filesystem::path(file).stem().string(),
                           MatrixOfResults(file, dataset.size()), outcome.truth, request.learning,
                           std::nullopt, request.fixed_thresholds));
    }
    WriteEvaluationResults(out_dir, dataset, outcome);
    return outcome;
}

}  // namespace lidarloop::app

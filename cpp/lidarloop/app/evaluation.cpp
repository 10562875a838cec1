#include "lidarloop/app/evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/evaluation_report.hpp"
#include "lidarloop/app/metrics_json.hpp"
#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/results_csv.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"

namespace lidarloop::app {
namespace {

std::string FirstPartName(const eval::ThresholdLearningConfig& learning);

void LearnThreshold(MethodEvaluation& e, const std::vector<eval::ScoredPair>& pairs,
                    std::size_t scans, const eval::ThresholdLearningConfig& learning,
                    const TrainingPairs* training) {
    try {
        if (training != nullptr) {
            e.learnt = eval::LearnAndTest(training->pairs, pairs, learning.criterion);
            e.learnt_on = training->source;
        } else {
            e.learnt = eval::LearnOnFirstPart(pairs, scans, learning);
            e.learnt_on = FirstPartName(learning);
        }
    } catch (const core::EmptyInputError&) {
        // Too short a sequence to split, or no pairs: the learnt row is left out of the report.
    }
}

void EvaluatePerScan(MethodEvaluation& e, std::vector<eval::BestMatch> best_matches,
                     const eval::GroundTruth& truth) {
    e.best_matches = std::move(best_matches);
    e.per_scan = eval::EvaluatePerScan(e.best_matches, truth);
    for (const eval::BestMatch& m : e.best_matches) e.smallest_differences.push_back(m.distance);
    e.em = eval::EstimateDifferenceThreshold(e.smallest_differences);
    e.distinctiveness = eval::SummarizeDistinctiveness(e.best_matches);
    if (e.default_threshold) {
        e.per_scan_at_default =
            eval::CountLabels(eval::LabelScans(e.best_matches, truth, *e.default_threshold));
    }
}

constexpr std::size_t kStreamRows = 64;      // rows of a block, one task
constexpr std::size_t kStreamColumns = 512;  // columns of a tile: the rows' descriptors stay cached

void StreamBlock(eval::StreamedPairwise::Sink& sink, std::size_t row_begin, std::size_t row_end,
                 std::size_t n, const eval::PairDistance& distance) {
    for (std::size_t column = row_begin + 1; column < n; column += kStreamColumns) {
        const std::size_t column_end = std::min(n, column + kStreamColumns);
        for (std::size_t i = row_begin; i < row_end; ++i) {
            for (std::size_t j = std::max(column, i + 1); j < column_end; ++j)
                sink.Add(i, j, distance(i, j));
        }
    }
}

// Pairs i < j of n scans with i < row: rows of n - 1, n - 2, ... pairs.
std::size_t PairsBeforeRow(std::size_t row, std::size_t n) { return row * (2 * n - row - 1) / 2; }

// Streams every pair i < j through `evaluation`, blocks of rows in parallel, one sink a thread,
// pass after pass, telling `progress` the pairs done (stage "pairs (<name>), pass p of 2").
eval::StreamedResult StreamPairs(eval::StreamedPairwise& evaluation, std::size_t n,
                                 const eval::PairDistance& distance, const std::string& name,
                                 const Progress& progress) {
    const std::size_t blocks = (n + kStreamRows - 1) / kStreamRows;
    const std::size_t total = PairsBeforeRow(n, n);
    while (!evaluation.finished()) {
        const std::string stage =
            "pairs (" + name + "), pass " + std::to_string(evaluation.pass()) + " of 2";
        pipeline::ProgressCounter done(StageReport(progress, stage), total);
        tbb::enumerable_thread_specific<eval::StreamedPairwise::Sink> sinks(
            [&] { return evaluation.NewSink(); });
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks, 1),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              eval::StreamedPairwise::Sink& sink = sinks.local();
                              for (std::size_t b = range.begin(); b < range.end(); ++b) {
                                  const std::size_t begin = b * kStreamRows;
                                  const std::size_t end = std::min(n, begin + kStreamRows);
                                  StreamBlock(sink, begin, end, n, distance);
                                  const std::size_t pairs =
                                      PairsBeforeRow(end, n) - PairsBeforeRow(begin, n);
                                  done.Add(pairs);
                              }
                          });
        for (eval::StreamedPairwise::Sink& sink : sinks) evaluation.Merge(sink);
        evaluation.EndPass();
    }
    return evaluation.Result();
}

eval::PairDistance MatrixDistance(const pipeline::SimilarityMatrix& matrix) {
    return
        [&matrix](std::size_t i, std::size_t j) { return matrix.condensed()[matrix.Index(i, j)]; };
}

eval::PairDistance DatabaseDistance(const pipeline::DescriptorDatabase& database) {
    return [&database](std::size_t i, std::size_t j) {
        return static_cast<float>(database.Distance(i, j));
    };
}

std::string FirstPartName(const eval::ThresholdLearningConfig& learning) {
    return "the queries of the first " +
           std::to_string(std::lround(100.0 * learning.train_fraction)) + " % of the scans";
}

// A pair of a results file must name scans of the dataset, and a finite distance must stay
// finite in the float matrix: overflowing to +inf would silently make it "never detected".
void CheckResult(const std::filesystem::path& file, const io::ExternalResult& r,
                 std::size_t scans) {
    const std::string pair = (r.line > 0 ? "line " + std::to_string(r.line) + ": " : "") +
                             "pair (" + std::to_string(r.query) + ", " + std::to_string(r.match) +
                             ")";
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

// A pair of a results file, scans ordered i < j.
struct ListedPair {
    std::size_t i;
    std::size_t j;
    float distance;
};

// The pairs `file` lists, in file order, each checked (CheckResult); a scan paired with itself
// is left out.
std::vector<ListedPair> ListedPairs(const std::filesystem::path& file, std::size_t scans) {
    std::vector<ListedPair> listed;
    for (const io::ExternalResult& r : io::ReadResultsCsv(file)) {
        CheckResult(file, r, scans);
        if (r.query == r.match) continue;
        listed.push_back({std::min(r.query, r.match), std::max(r.query, r.match),
                          static_cast<float>(r.distance)});
    }
    return listed;
}

void RequirePoses(const io::Dataset& dataset, const std::string& role,
                  const std::string& poses_flag) {
    if (!dataset.HasPoses()) {
        throw core::ConfigError(dataset.root().string() + " has no poses; " + role +
                                " needs ground truth (" + poses_flag + " FILE)");
    }
}

// The threshold learnt on every pair of the training dataset under the evaluation's
// ground-truth rule (streamed); nullopt without a pair or a finite distance there, as
// LearnAndTest's EmptyInputError leaves the learnt row out.
std::optional<LearntThreshold> TrainingThresholdOf(const EvaluationRequest& request,
                                                   const core::DescriptorConfig& descriptor,
                                                   const io::Dataset& train_dataset) {
    const auto described =
        DescribeDataset(train_dataset, descriptor,
                        {"training set (" + core::ToString(descriptor.method) + ")",
                         request.skip_bad,
                         pipeline::Execution::kParallel,
                         request.progress,
                         {}});
    const eval::GroundTruth truth =
        eval::BuildGroundTruth(train_dataset.poses(), GroundTruthRule(request));
    const eval::PairDistance distance = DatabaseDistance(described.database);
    eval::StreamedPairwise evaluation(truth, eval::ScorePositives(truth, distance), {});
    eval::StreamedResult result;
    try {
        result =
            StreamPairs(evaluation, truth.size(), distance,
                        "training set, " + core::ToString(descriptor.method), request.progress);
    } catch (const core::EmptyInputError&) {
        return std::nullopt;
    }
    if (result.pairwise.distinct_thresholds == 0) return std::nullopt;
    const eval::Criterion criterion = request.learning.criterion;
    return LearntThreshold{
        "all pairs of " + train_dataset.root().string(), criterion,
        criterion == eval::Criterion::kMcc ? result.pairwise.best_mcc : result.pairwise.best_f1};
}

// Whether `odometry` places every scan where the ground truth does (to a millimetre).
bool IsTheGroundTruth(const std::vector<core::StampedPose>& odometry,
                      const std::vector<core::StampedPose>& truth) {
    if (odometry.size() != truth.size()) return false;
    for (std::size_t i = 0; i < odometry.size(); ++i) {
        const Eigen::Vector3d offset =
            odometry[i].T_world_sensor.translation() - truth[i].T_world_sensor.translation();
        if (!(offset.norm() <= 1e-3)) return false;
    }
    return true;
}

// Scans prepared for verification once per evaluation: while the first method describes them
// (and then as submaps when the odometry is known).
struct VerificationState {
    std::optional<PreparedScans> prepared;
    bool collected = false;
    pipeline::VerificationCache cache;
};

const std::vector<core::StampedPose> kNoOdometry;

// Scan i's submap replaces it once every scan has been read (skipped scans are then known),
// placed by the odometry or, without it, by the scans' registrations to their neighbours.
void CollectPrepared(const io::Dataset& dataset, const io::RunConfig& config,
                     const OdometryCheck* odometry, const Progress& progress,
                     VerificationState& verification) {
    PrepareSubmapsIfAsked(dataset, odometry != nullptr ? odometry->odometry : kNoOdometry,
                          config.detection.verification, *verification.prepared, progress);
}

MethodEvaluation EvaluateMethod(const EvaluationRequest& request, core::Method method,
                                const io::Dataset& dataset, const eval::GroundTruth& truth,
                                const io::Dataset* train_dataset, const OdometryCheck* odometry,
                                VerificationState& verification) {
    io::RunConfig config = request.config;
    config.descriptor.method = method;
    std::optional<LearntThreshold> training;
    if (train_dataset != nullptr)
        training = TrainingThresholdOf(request, config.descriptor, *train_dataset);
    DescribeRun run{"describing (" + core::ToString(method) + ")",
                    request.skip_bad,
                    pipeline::Execution::kParallel,
                    request.progress,
                    {}};
    const bool collecting = verification.prepared && !verification.collected;
    if (collecting) {
        const auto& reduction = config.detection.verification.reduction;
        // Without odometry each scan is prepared alone first: its neighbours place the submaps.
        run.with_cloud = odometry != nullptr ? verification.prepared->CollectorFor(reduction)
                                             : verification.prepared->Collector(reduction);
        verification.collected = true;
    }
    const auto described = DescribeDataset(dataset, config.descriptor, run);
    if (collecting) CollectPrepared(dataset, config, odometry, request.progress, verification);
    const pipeline::DescriptorDatabase& database = described.database;
    const bool keep_matrix = config.output.KeepsSimilarityMatrix(database.size());
    pipeline::SimilarityMatrix matrix;
    eval::PairDistance distance = DatabaseDistance(database);
    Stopwatch matrix_clock;
    if (keep_matrix) {
        matrix = pipeline::ComputeSimilarityMatrix(database);
        distance = MatrixDistance(matrix);
    }
    const double matrix_s = matrix_clock.Seconds();
    Stopwatch streamed_clock;
    MethodEvaluation e = EvaluateStreamed(core::ToString(method), distance, truth, request.learning,
                                          config.detection.ThresholdFor(method),
                                          request.fixed_thresholds, training, request.progress);
    // Without the matrix each pass computes every distance once: two comparisons a pair.
    const double comparisons_s = keep_matrix ? matrix_s : streamed_clock.Seconds() / 2.0;
    const double pairs = static_cast<double>(eval::CondensedSize(database.size()));
    e.describe_ms_per_scan_median = 1e3 * Quantile(described.describe_seconds, 0.5);
    e.skipped = described.skipped;
    e.ns_per_comparison = pairs > 0 ? 1e9 * comparisons_s / pairs : 0.0;
    e.matrix = std::move(matrix);
    const PreparedScans* prepared = verification.prepared ? &*verification.prepared : nullptr;
    e.retrieval = keep_matrix ? CompareRetrieval(e.matrix, database.times_s(), config.detection,
                                                 method, truth, dataset.poses(), prepared,
                                                 &verification.cache, request.progress, odometry)
                              : CompareRetrieval(
                                    pipeline::DetectStreaming(
                                        database, config.detection, pipeline::Execution::kParallel,
                                        DetectorPathM(truth, odometry),
                                        VerificationCheckOf(odometry, config.detection, prepared)),
                                    config.detection, method, truth, dataset.poses(), prepared,
                                    &verification.cache, request.progress, odometry);
    return e;
}

// A results file's pairs, kept as a matrix for the images only when it fits the budget.
MethodEvaluation EvaluateResults(const EvaluationRequest& request, const std::string& file,
                                 std::size_t scans, const eval::GroundTruth& truth) {
    const std::string name = "results:" + std::filesystem::path(file).stem().string();
    if (!request.config.output.KeepsSimilarityMatrix(scans)) {
        return EvaluateStreamed(name, DistancesOfResults(file, scans), truth, request.learning,
                                std::nullopt, request.fixed_thresholds, std::nullopt,
                                request.progress);
    }
    pipeline::SimilarityMatrix matrix = MatrixOfResults(file, scans);
    MethodEvaluation e =
        EvaluateStreamed(name, MatrixDistance(matrix), truth, request.learning, std::nullopt,
                         request.fixed_thresholds, std::nullopt, request.progress);
    e.matrix = std::move(matrix);
    return e;
}

// Every method reads the same files, so the first one's skipped scans are all of them.
void NoteSkippedScans(const std::filesystem::path& out_dir, EvaluationOutcome& outcome) {
    if (outcome.methods.empty() || outcome.methods.front().skipped.empty()) return;
    outcome.skipped = outcome.methods.front().skipped;
    WriteSkipped(out_dir, outcome.skipped);
    const std::size_t count = outcome.skipped.size();
    outcome.notes.push_back(std::to_string(count) + (count == 1 ? " scan" : " scans") +
                            " could not be read (skipped.txt): each stands in as a scan that "
                            "matches nothing, so its revisits count as missed");
}

void WriteEvaluationResults(const std::filesystem::path& out_dir, const io::Dataset& dataset,
                            EvaluationOutcome& outcome) {
    const eval::GroundTruth& truth = outcome.truth;
    WriteJson(out_dir / "metrics.json",
              EvaluationMetricsJson(dataset.root().string(), dataset.size(), outcome));
    WriteCurveCsvs(out_dir, outcome.methods);
    std::vector<std::string> notes = WriteFigures(out_dir, truth, outcome.methods);
    outcome.notes.insert(outcome.notes.begin(), notes.begin(), notes.end());
    // The pair protocol needs both classes: one alone makes every threshold perfect (MCC 0,
    // F1 1) or empty, figures that read as results.
    if (!outcome.methods.empty()) {
        const eval::PairwiseEvaluation& pairs = outcome.methods.front().pairwise;
        if (pairs.positives == 0 || pairs.negatives == 0) {
            outcome.notes.push_back(
                std::string("every compared pair is ") +
                (pairs.positives == 0 ? "a different place" : "the same place") + " (no " +
                (pairs.positives == 0 ? "positive" : "negative") +
                " pair at --distance): the pair protocol's MCC, F1, ROC and recall at zero "
                "errors say nothing here");
        }
    }
    for (const MethodEvaluation& e : outcome.methods) {
        if (e.optimum_exact) continue;
        outcome.notes.push_back(
            e.name +
            ": the MCC is negative at every positive pair's distance, and the streamed "
            "evaluation does not visit the thresholds between them, where the best MCC could "
            "be higher (docs/evaluation.md, evaluation in linear memory)");
    }
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
    EvaluatePerScan(e, eval::BestMatchesFromCondensed(e.matrix.condensed(), truth), truth);
    return e;
}

MethodEvaluation EvaluateStreamed(std::string name, const eval::PairDistance& distance,
                                  const eval::GroundTruth& truth,
                                  const eval::ThresholdLearningConfig& learning,
                                  std::optional<double> default_threshold,
                                  const std::vector<double>& fixed_thresholds,
                                  const std::optional<LearntThreshold>& training,
                                  const Progress& progress) {
    MethodEvaluation e;
    e.name = std::move(name);
    e.default_threshold = default_threshold;
    e.fixed_thresholds = fixed_thresholds;
    // The confusions wanted: the fixed thresholds, then the default, then the learnt one.
    eval::StreamedRequest request;
    request.thresholds = fixed_thresholds;
    if (default_threshold) request.thresholds.push_back(*default_threshold);
    if (training) {
        request.thresholds.push_back(training->best.threshold);
    } else {
        request.learning = learning;
    }
    eval::StreamedPairwise evaluation(truth, eval::ScorePositives(truth, distance), request);
    eval::StreamedResult result = StreamPairs(evaluation, truth.size(), distance, e.name, progress);
    e.pairwise = std::move(result.pairwise);
    e.optimum_exact = result.optimum_exact;
    const auto& at = result.at_thresholds;
    e.at_fixed.assign(at.begin(),
                      at.begin() + static_cast<std::ptrdiff_t>(fixed_thresholds.size()));
    if (default_threshold) e.at_default = at[fixed_thresholds.size()];
    if (training) {
        e.learnt = eval::TransferOf(training->criterion, training->best, at.back());
        e.learnt_on = training->source;
    } else if (result.learnt) {
        e.learnt = result.learnt;
        e.learnt_on = FirstPartName(learning);
    }
    EvaluatePerScan(e, std::move(result.best_matches), truth);
    return e;
}

pipeline::SimilarityMatrix MatrixOfResults(const std::filesystem::path& file, std::size_t scans) {
    // +inf: never detected (eval::ScoredPair), the rule for every pair the file leaves out.
    pipeline::SimilarityMatrix matrix(scans);
    std::fill(matrix.condensed().begin(), matrix.condensed().end(),
              std::numeric_limits<float>::infinity());
    for (const ListedPair& p : ListedPairs(file, scans))
        matrix.set(p.i, p.j, std::min(matrix.at(p.i, p.j), p.distance));
    return matrix;
}

eval::PairDistance DistancesOfResults(const std::filesystem::path& file, std::size_t scans) {
    std::vector<ListedPair> listed = ListedPairs(file, scans);
    // Pairs listed twice keep the smallest distance, folded in file order as MatrixOfResults.
    std::stable_sort(listed.begin(), listed.end(), [](const ListedPair& a, const ListedPair& b) {
        return a.i != b.i ? a.i < b.i : a.j < b.j;
    });
    struct Rows {
        std::vector<std::size_t> offsets;  // pairs of row i: [offsets[i], offsets[i + 1])
        std::vector<std::size_t> columns;
        std::vector<float> distances;
    };
    auto rows = std::make_shared<Rows>();
    rows->offsets.assign(scans + 1, 0);
    for (std::size_t k = 0; k < listed.size(); ++k) {
        const ListedPair& p = listed[k];
        if (k > 0 && listed[k - 1].i == p.i && listed[k - 1].j == p.j) {
            rows->distances.back() = std::min(rows->distances.back(), p.distance);
            continue;
        }
        rows->columns.push_back(p.j);
        rows->distances.push_back(std::min(std::numeric_limits<float>::infinity(), p.distance));
        ++rows->offsets[p.i + 1];
    }
    for (std::size_t i = 0; i < scans; ++i) rows->offsets[i + 1] += rows->offsets[i];
    return [rows](std::size_t i, std::size_t j) {
        const auto begin = rows->columns.begin() + static_cast<std::ptrdiff_t>(rows->offsets[i]);
        const auto end = rows->columns.begin() + static_cast<std::ptrdiff_t>(rows->offsets[i + 1]);
        const auto at = std::lower_bound(begin, end, j);
        return at != end && *at == j
                   ? rows->distances[static_cast<std::size_t>(at - rows->columns.begin())]
                   : std::numeric_limits<float>::infinity();
    };
}

eval::GroundTruthConfig GroundTruthRule(const EvaluationRequest& request) {
    eval::GroundTruthConfig rule;
    rule.distance_m = request.distance_m;
    rule.max_heading_deg = request.max_heading_deg;
    rule.min_gap = request.config.detection.min_gap;
    rule.min_path_m = request.config.detection.min_path_m;  // the detector's own rule
    rule.Validate();
    return rule;
}

EvaluationOutcome RunEvaluation(const io::Dataset& dataset, const EvaluationRequest& request,
                                const io::Dataset* train_dataset) {
    request.learning.Validate();
    if (request.methods.empty() && request.results_files.empty())
        throw core::ConfigError("nothing to evaluate: give a method or a results file");
    // A threshold may be negative (a results file of negated similarities) or +inf (every
    // finite pair detected), but a NaN decides nothing.
    for (const double threshold : request.fixed_thresholds) {
        if (std::isnan(threshold))
            throw core::ConfigError("fixed_thresholds must be numbers, got nan");
    }
    const auto& methods = request.methods;
    for (auto method = methods.begin(); method != methods.end(); ++method) {
        if (std::find(methods.begin(), method, *method) != method) {
            throw core::ConfigError("method " + core::ToString(*method) +
                                    " is asked for twice; each method is evaluated once");
        }
    }
    if (request.config.detection.threshold && request.methods.size() > 1) {
        throw core::ConfigError(
            "detection.threshold (" + core::NumberText(*request.config.detection.threshold) +
            ") is the threshold of one method; evaluate one method with it, or leave it default");
    }
    RequirePoses(dataset, "evaluation", "--poses");
    if (train_dataset != nullptr)
        RequirePoses(*train_dataset, "threshold learning", "--train-poses");
    EvaluationOutcome outcome{
        eval::BuildGroundTruth(dataset.poses(), GroundTruthRule(request)), {}, {}, {}};
    const std::vector<core::StampedPose> odometry =
        ReadOdometryIfGiven(request.odometry_file, request.odometry_topic, dataset,
                            request.config.posegraph.max_odometry_step_m, request.odometry_calib);
    if (!odometry.empty() && request.config.detection.verify &&
        IsTheGroundTruth(odometry, dataset.poses())) {
        outcome.notes.push_back(
            "the odometry is the ground truth the loops are scored against (the same "
            "positions): submaps placed and loops checked by it flatter the verified figures; "
            "give the sequence's own odometry");
    }
    for (std::string& note : FramesNotes(dataset, odometry))
        outcome.notes.push_back(std::move(note));
    if (std::string note = UnusedOdometryNote(dataset, odometry, request.config.detection.verify);
        !note.empty())
        outcome.notes.push_back(std::move(note));
    EvaluationRequest effective = request;
    // Submaps from the odometry or the scans themselves: placed by the dataset's poses, the
    // ground truth scored against here, they would flatter the verified recall.
    effective.config = WithSubmapsWhereTheyApply(request.config, dataset, odometry, outcome.notes,
                                                 NeighboursPlaceSubmaps(dataset, odometry), true);
    const std::filesystem::path out_dir = PrepareOutputFolder(request.out);
    io::WriteConfigYaml(out_dir / "config.yaml", effective.config);
    VerificationState verification;
    if (effective.config.detection.verify) verification.prepared.emplace(dataset.size());
    std::optional<OdometryCheck> odometry_check;
    if (!odometry.empty()) {
        odometry_check =
            OdometryCheck{odometry, core::CumulativePathM(odometry), effective.config.posegraph};
    }
    for (core::Method method : request.methods) {
        outcome.methods.push_back(
            EvaluateMethod(effective, method, dataset, outcome.truth, train_dataset,
                           odometry_check ? &*odometry_check : nullptr, verification));
    }
    for (const std::string& file : request.results_files) {
        outcome.methods.push_back(EvaluateResults(request, file, dataset.size(), outcome.truth));
    }
    NoteSkippedScans(out_dir, outcome);
    WriteEvaluationResults(out_dir, dataset, outcome);
    return outcome;
}

}  // namespace lidarloop::app

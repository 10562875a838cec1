#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "lidarloop/app/progress.hpp"
#include "lidarloop/app/retrieval_evaluation.hpp"
#include "lidarloop/eval/em.hpp"
#include "lidarloop/eval/ground_truth.hpp"
#include "lidarloop/eval/pairwise.hpp"
#include "lidarloop/eval/per_scan.hpp"
#include "lidarloop/eval/streamed_pairwise.hpp"
#include "lidarloop/eval/summary.hpp"
#include "lidarloop/eval/threshold_learning.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

namespace lidarloop::app {

/// Everything the evaluation computed for one method (or one external results file) on one
/// ground truth: both papers' protocols side by side.
struct MethodEvaluation {
    std::string name;                         ///< height, range, ndt, or results:<file>
    std::optional<double> default_threshold;  ///< the method's default tau / t_d, when a method
    /// The distances, kept only within output.similarity_matrix_mib (else size 0): the
    /// evaluation itself streams the pairs (eval::StreamedPairwise).
    pipeline::SimilarityMatrix matrix;
    /// False when the best MCC may miss a threshold between two positives' distances
    /// (eval::StreamedResult::optimum_exact); always true for EvaluateMatrix.
    bool optimum_exact = true;
    eval::PairwiseEvaluation pairwise;              ///< Röhling IV-B/C
    std::optional<eval::ThresholdTransfer> learnt;  ///< table I: learnt on training pairs
    std::string learnt_on;  ///< where they came from: the first part or another dataset
    std::optional<eval::Confusion> at_default;                ///< L_tau at the default threshold
    std::vector<double> fixed_thresholds;                     ///< Röhling table II columns
    std::vector<eval::Confusion> at_fixed;                    ///< L_tau at each of them
    std::vector<eval::BestMatch> best_matches;                ///< per scan (Magnusson II-E)
    eval::PerScanEvaluation per_scan;                         ///< table I taxonomy, fig. 1
    std::optional<eval::TaxonomyCounts> per_scan_at_default;  ///< the taxonomy at the default
    std::vector<double> smallest_differences;
    eval::DifferenceThreshold em;  ///< fig. 2
    eval::DistinctivenessSummary distinctiveness;
    /// The online detector's top-k candidates, descriptor alone and verified (methods only).
    std::optional<RetrievalComparison> retrieval;
    double describe_ms_per_scan_median = 0.0;
    double ns_per_comparison = 0.0;
    /// "scan 17: <reason>" per scan that could not be read (EvaluationRequest::skip_bad): it
    /// stands in as a scan that matches nothing.
    std::vector<std::string> skipped;
};

/// Scored pairs of another dataset to learn the threshold on (Röhling table I: learnt on one
/// route, tested on another).
struct TrainingPairs {
    std::string source;  ///< e.g. the dataset's folder
    std::vector<eval::ScoredPair> pairs;
};

/// Evaluates a finished similarity matrix against `truth` with every pair in memory (O(n^2)):
/// the reference of EvaluateStreamed, which RunEvaluation uses. The threshold is learnt on
/// `training` when given, else on the first part of this sequence (learning.train_fraction).
MethodEvaluation EvaluateMatrix(std::string name, pipeline::SimilarityMatrix matrix,
                                const eval::GroundTruth& truth,
                                const eval::ThresholdLearningConfig& learning,
                                std::optional<double> default_threshold,
                                const std::vector<double>& fixed_thresholds = {},
                                const TrainingPairs* training = nullptr);

/// A threshold learnt on all pairs of another dataset (Röhling table I), for EvaluateStreamed.
struct LearntThreshold {
    std::string source;  ///< e.g. "all pairs of <folder>"
    eval::Criterion criterion = eval::Criterion::kMcc;
    eval::BestThreshold best;  ///< the training optimum: tau, its score and confusion
};

/// EvaluateMatrix without the matrix, in memory O(n + positives): the pairs are streamed from
/// `distance` twice in parallel (oneTBB), and every figure equals EvaluateMatrix's on the same
/// distances, up to MethodEvaluation::optimum_exact. `matrix` is left empty; the threshold is
/// learnt on `training` when given, else on the first part of this sequence. `progress` is told
/// the pairs done of each pass (stage "pairs (<name>), pass p of 2"), from worker threads.
MethodEvaluation EvaluateStreamed(std::string name, const eval::PairDistance& distance,
                                  const eval::GroundTruth& truth,
                                  const eval::ThresholdLearningConfig& learning,
                                  std::optional<double> default_threshold,
                                  const std::vector<double>& fixed_thresholds = {},
                                  const std::optional<LearntThreshold>& training = std::nullopt,
                                  const Progress& progress = {});

/// The distances of an external detector's `query,match,distance` CSV as MatrixOfResults has
/// them, in memory O(listed pairs): +inf for every pair the file leaves out. io::ReadError as
/// MatrixOfResults.
eval::PairDistance DistancesOfResults(const std::filesystem::path& file, std::size_t scans);

/// The similarity matrix of an external detector's `query,match,distance` CSV: listed pairs get
/// their distance (the smallest when listed twice), every other pair +inf, which the evaluation
/// never detects at any threshold (eval::ScoredPair); a scan the file never lists has no match.
/// io::ReadError when a pair names a scan beyond `scans` or a finite distance overflows a float.
pipeline::SimilarityMatrix MatrixOfResults(const std::filesystem::path& file, std::size_t scans);

/// What `lidarloop evaluate` (and `lidarloop demo`) asks for.
struct EvaluationRequest {
    /// Descriptors, and detection.min_gap (S) and min_path_m as the evaluation's rule of which
    /// pairs may be revisits (eval::GroundTruthConfig), the rule the detector's candidates obey.
    io::RunConfig config;
    std::vector<core::Method> methods;
    std::vector<std::string> results_files;  ///< other detectors' query,match,distance CSVs
    double distance_m = 10.0;                ///< same place when closer (Röhling d, Magnusson t_r)
    double max_heading_deg = 0.0;            ///< and headings closer than this; 0: any
    eval::ThresholdLearningConfig learning;
    std::vector<double> fixed_thresholds;  ///< MCC at each, as Röhling's table II
    bool skip_bad = false;
    /// Odometry, KITTI or TUM, one pose per scan (never the ground truth): verification then
    /// registers submaps placed by it and rejects loops it contradicts, as `detect --odometry`.
    /// Empty: submaps placed by each scan's registration to the one before, as `detect`.
    std::filesystem::path odometry_file;
    std::string odometry_topic;  ///< instead of odometry_file, for a bag: its Odometry topic
    std::filesystem::path odometry_calib;  ///< as DetectRequest::odometry_calib
    Progress progress;
    std::filesystem::path out;  ///< the results folder (created)
};

struct EvaluationOutcome {
    eval::GroundTruth truth;
    std::vector<MethodEvaluation> methods;
    std::vector<std::string> notes;    ///< figures that could not be drawn
    std::vector<std::string> skipped;  ///< the scans no method could read (skipped.txt)
};

/// The ground-truth rule of `request`: its distance, heading, minimum path and the config's
/// minimum gap.
eval::GroundTruthConfig GroundTruthRule(const EvaluationRequest& request);

/// Evaluates every method and results file on one ground truth from the dataset's poses
/// (EvaluateStreamed: memory linear in the scans; the matrices are kept for the images only
/// within config.output.similarity_matrix_mib) and
/// writes config.yaml, metrics.json, roc.csv, pr.csv, the images and figures and report.md into
/// request.out. Every method's top-k candidates (config.detection) are also scored as the
/// online detector reports them, and with config.detection.verify after geometric verification
/// (each scan prepared once, each pair registered once for all methods). With `train_dataset`
/// (which needs poses too), each method's threshold is learnt on all its pairs under the same
/// ground-truth rule and tested on all pairs of `dataset`; results files keep learning on the first
/// part. ConfigError when a dataset has no poses, or when config.detection.threshold is set and
/// more than one method is evaluated.
EvaluationOutcome RunEvaluation(const io::Dataset& dataset, const EvaluationRequest& request,
                                const io::Dataset* train_dataset = nullptr);

}  // namespace lidarloop::app

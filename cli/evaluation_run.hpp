#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarloop/eval/em.hpp"
#include "lidarloop/eval/ground_truth.hpp"
#include "lidarloop/eval/pairwise.hpp"
#include "lidarloop/eval/per_scan.hpp"
#include "lidarloop/eval/summary.hpp"
#include "lidarloop/eval/threshold_learning.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

namespace lidarloop::cli {

/// Everything the evaluation computed for one method (or one external results file) on one
/// ground truth: both papers' protocols side by side.
struct MethodEvaluation {
    std::string name;                         ///< height, range, ndt, or results:<file>
    std::optional<double> default_threshold;  ///< the config's tau / t_d, when a method
    pipeline::SimilarityMatrix matrix;
    eval::PairwiseEvaluation pairwise;              ///< Röhling IV-B/C
    std::optional<eval::ThresholdTransfer> learnt;  ///< table I: learnt on training pairs
    std::string learnt_on;  ///< where they came from: the first part or another dataset
    std::optional<eval::Confusion> at_default;  ///< L_tau at the default threshold
    std::vector<double> fixed_thresholds;       ///< Röhling table II columns
    std::vector<eval::Confusion> at_fixed;      ///< L_tau at each of them
    std::vector<eval::BestMatch> best_matches;  ///< per scan (Magnusson II-E)
    eval::PerScanEvaluation per_scan;           ///< table I taxonomy, fig. 1
    std::vector<double> smallest_differences;
    eval::DifferenceThreshold em;  ///< fig. 2
    eval::DistinctivenessSummary distinctiveness;
    double describe_ms_per_scan_median = 0.0;
    double ns_per_comparison = 0.0;
};

/// Scored pairs of another dataset to learn the threshold on (Röhling table I: learnt on one
/// route, tested on another).
struct TrainingPairs {
    std::string source;  ///< e.g. the dataset's folder
    std::vector<eval::ScoredPair> pairs;
};

/// Evaluates a finished similarity matrix against `truth`. The threshold is learnt on
/// `training` when given, else on the first part of this sequence (learning.train_fraction).
MethodEvaluation EvaluateMatrix(std::string name, pipeline::SimilarityMatrix matrix,
                                const eval::GroundTruth& truth,
                                const eval::ThresholdLearningConfig& learning,
                                std::optional<double> default_threshold,
                                const std::vector<double>& fixed_thresholds = {},
                                const TrainingPairs* training = nullptr);

/// metrics.json's entry for one method.
nlohmann::json MetricsJson(const MethodEvaluation& evaluation);

}  // namespace lidarloop::cli

#include "evaluation_run.hpp"

#include <cmath>
#include <limits>

#include "lidarloop/core/error.hpp"

namespace lidarloop::cli {
namespace {

nlohmann::json ConfusionJson(const eval::Confusion& c) {
    return {{"tp", c.tp},
            {"fp", c.fp},
            {"tn", c.tn},
            {"fn", c.fn},
            {"f1", eval::F1(c)},
            {"mcc", eval::Mcc(c)},
            {"precision", eval::Precision(c)},
            {"recall", eval::Recall(c)}};
}

nlohmann::json TaxonomyJson(const eval::TaxonomyCounts& c) {
    return {{"true_positive", c.true_positive},   {"mismatch", c.mismatch},
            {"false_positive", c.false_positive}, {"true_negative", c.true_negative},
            {"false_negative", c.false_negative}, {"recall", c.Recall()}};
}

// JSON has no infinity: an unbounded threshold is written as null.
nlohmann::json Finite(double value) {
    return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
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
    try {
        if (training != nullptr) {
            e.learnt = eval::LearnAndTest(training->pairs, pairs, learning.criterion);
            e.learnt_on = training->source;
        } else {
            e.learnt = eval::LearnOnFirstPart(pairs, truth.size(), learning);
            e.learnt_on = "the queries of the first " +
                          std::to_string(std::lround(100.0 * learning.train_fraction)) +
                          " % of the scans";
        }
    } catch (const core::EmptyInputError&) {
        // Too short a sequence to split, or no pairs: the learnt row is left out of the report.
    }
    if (default_threshold) e.at_default = eval::ConfusionAt(pairs, *default_threshold);
    e.fixed_thresholds = fixed_thresholds;
    e.at_fixed = eval::ConfusionsAt(pairs, fixed_thresholds);
    e.best_matches = eval::BestMatchesFromCondensed(e.matrix.condensed(), truth);
    e.per_scan = eval::EvaluatePerScan(e.best_matches, truth);
    for (const eval::BestMatch& m : e.best_matches) e.smallest_differences.push_back(m.distance);
    e.em = eval::EstimateDifferenceThreshold(e.smallest_differences);
    e.distinctiveness = eval::SummarizeDistinctiveness(e.best_matches);
    return e;
}

nlohmann::json MetricsJson(const MethodEvaluation& e) {
    const eval::PairwiseEvaluation& p = e.pairwise;
    nlohmann::json json;
    json["best_mcc"] = p.best_mcc.score;
    json["tau_best_mcc"] = p.best_mcc.threshold;
    json["best_f1"] = p.best_f1.score;
    json["tau_best_f1"] = p.best_f1.threshold;
    json["roc_auc"] = p.roc_auc ? nlohmann::json(*p.roc_auc) : nlohmann::json(nullptr);
    json["recall_at_zero_fp"] = e.per_scan.zero_error.recall;
    json["tau_zero_fp"] = Finite(e.per_scan.zero_error.t_d);
    json["em_threshold"] = e.em.t_d ? nlohmann::json(*e.em.t_d) : nlohmann::json(nullptr);
    json["counts"] = {{"pairs", p.pairs},
                      {"positive_pairs", p.positives},
                      {"negative_pairs", p.negatives},
                      {"overlapping_scans", e.per_scan.overlapping},
                      {"non_overlapping_scans", e.per_scan.non_overlapping}};
    json["at_best_mcc"] = ConfusionJson(p.best_mcc.confusion);
    json["at_best_f1"] = ConfusionJson(p.best_f1.confusion);
    if (e.default_threshold) {
        json["default_threshold"] = *e.default_threshold;
        json["at_default_threshold"] = ConfusionJson(*e.at_default);
    }
    if (e.learnt) {
        json["threshold_learning"] = {{"trained_on", e.learnt_on},
                                      {"criterion", eval::ToString(e.learnt->criterion)},
                                      {"tau", e.learnt->threshold},
                                      {"train_score", e.learnt->train_score},
                                      {"test_f1", e.learnt->test_f1},
                                      {"test_mcc", e.learnt->test_mcc},
                                      {"test", ConfusionJson(e.learnt->test)}};
    }
    json["at_fixed_thresholds"] = nlohmann::json::array();
    for (std::size_t t = 0; t < e.fixed_thresholds.size(); ++t) {
        nlohmann::json entry = ConfusionJson(e.at_fixed[t]);
        entry["tau"] = e.fixed_thresholds[t];
        json["at_fixed_thresholds"].push_back(entry);
    }
    json["taxonomy_at_zero_fp"] = TaxonomyJson(e.per_scan.zero_error.counts);
    nlohmann::json components = nlohmann::json::array();
    for (const auto& c : e.em.fit.components) {
        components.push_back({{"weight", c.weight}, {"mean", c.mean}, {"stddev", c.stddev}});
    }
    json["em"] = {{"components", components}, {"log_likelihood", e.em.fit.log_likelihood}};
    if (e.distinctiveness.ratio) {
        const eval::Summary& r = *e.distinctiveness.ratio;
        json["second_ratio"] = {{"median", r.median}, {"p05", r.p05}, {"p95", r.p95}};
    }
    json["describe_ms_per_scan_median"] = e.describe_ms_per_scan_median;
    json["ns_per_comparison"] = e.ns_per_comparison;
    return json;
}

}  // namespace lidarloop::cli

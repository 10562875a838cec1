#include "lidarloop/app/metrics_json.hpp"

#include <cmath>

#include "lidarloop/app/results_folder.hpp"

namespace lidarloop::app {
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

// The thresholds the evaluation scored at besides the best ones: the default, the learnt one
// (with its test figures) and the fixed ones.
void AddThresholdRows(const MethodEvaluation& e, nlohmann::json& json) {
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
}

// Magnusson's per-scan view: the taxonomy at zero errors, the EM fit, distinctiveness.
void AddPerScanFigures(const MethodEvaluation& e, nlohmann::json& json) {
    json["taxonomy_at_zero_fp"] = TaxonomyJson(e.per_scan.zero_error.counts);
    json["em"] = nullptr;  // too few distinct smallest differences to fit
    if (e.em.Fitted()) {
        nlohmann::json components = nlohmann::json::array();
        for (const auto& c : e.em.fit.components) {
            components.push_back({{"weight", c.weight}, {"mean", c.mean}, {"stddev", c.stddev}});
        }
        json["em"] = {{"components", components}, {"log_likelihood", e.em.fit.log_likelihood}};
    }
    if (e.distinctiveness.ratio) {
        const eval::Summary& r = *e.distinctiveness.ratio;
        json["second_ratio"] = {{"median", r.median}, {"p05", r.p05}, {"p95", r.p95}};
    }
}

nlohmann::json DistributionJson(const std::optional<eval::Summary>& s) {
    if (!s) return nullptr;
    return {{"median", s->median}, {"p95", s->p95}, {"max", s->max}, {"mean", s->mean}};
}

// NaN (an undefined rate: no denominator) is written as null.
nlohmann::json Rate(double value) { return Finite(value); }

nlohmann::json RetrievalJson(const eval::LoopRetrievalEvaluation& r) {
    const eval::PoseErrorSummary& pose = r.pose_error;
    return {{"queries", r.queries},
            {"revisiting_scans", r.revisiting},
            {"recall_at_1", Rate(r.recall_at_1)},
            {"recall_at_k", Rate(r.recall_at_k)},
            {"true_loops", r.true_loops},
            {"false_loops", r.false_loops},
            {"loops_with_pose", r.loops_with_pose},
            {"wrong_pose_loops", r.wrong_pose_loops},
            {"precision", Rate(r.precision)},
            {"recall", Rate(r.recall)},
            {"recall_at_full_precision", Rate(r.full_precision.recall)},
            {"pose_error",
             {{"loops", pose.count},
              {"translation_m", DistributionJson(pose.translation_m)},
              {"planar_m", DistributionJson(pose.planar_m)},
              {"yaw_deg", DistributionJson(pose.yaw_deg)},
              {"rotation_deg", DistributionJson(pose.rotation_deg)}}}};
}

void AddRetrieval(const MethodEvaluation& e, nlohmann::json& json) {
    if (!e.retrieval) return;
    const RetrievalComparison& r = *e.retrieval;
    json["retrieval"]["k"] = r.top_k;
    json["retrieval"]["descriptor"] = RetrievalJson(r.descriptor);
    if (r.verified) {
        json["retrieval"]["verified"] = RetrievalJson(*r.verified);
        const auto ms = [](const std::vector<double>& seconds) {
            return SummaryJson(seconds, 1e3);
        };
        json["retrieval"]["verify_ms_per_pair"] = ms(r.verification_times.pair_seconds);
        json["retrieval"]["pairs_registered"] = r.verification_times.pair_seconds.size();
    }
}

}  // namespace

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
    AddThresholdRows(e, json);
    AddPerScanFigures(e, json);
    AddRetrieval(e, json);
    json["describe_ms_per_scan_median"] = e.describe_ms_per_scan_median;
    json["ns_per_comparison"] = e.ns_per_comparison;
    return json;
}

nlohmann::json EvaluationMetricsJson(const std::string& dataset, std::size_t scans,
                                     const EvaluationOutcome& outcome) {
    const eval::GroundTruth& truth = outcome.truth;
    nlohmann::json metrics;
    metrics["dataset"] = dataset;
    metrics["scans"] = scans;
    metrics["skipped_scans"] = outcome.skipped.size();
    metrics["ground_truth"] = {{"rule", truth.Describe()},
                               {"distance_m", truth.config.distance_m},
                               {"max_heading_deg", truth.config.max_heading_deg},
                               {"min_gap", truth.config.min_gap.value},
                               {"min_gap_unit", core::ToString(truth.config.min_gap.unit)},
                               {"min_path_m", truth.config.min_path_m}};
    for (const MethodEvaluation& e : outcome.methods) metrics["methods"][e.name] = MetricsJson(e);
    return metrics;
}

}  // namespace lidarloop::app

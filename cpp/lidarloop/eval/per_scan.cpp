#include "lidarloop/eval/per_scan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/detail/ratio.hpp"
#include "lidarloop/eval/pairwise.hpp"

namespace lidarloop::eval {
namespace {

// The label a scan gets when it is similar (its distance below t_d).
ScanLabel LabelIfSimilar(std::size_t i, const BestMatch& match, const GroundTruth& truth) {
    if (!truth.Overlapping(i)) return ScanLabel::kFalsePositive;
    return truth.IsLoop(i, match.match) ? ScanLabel::kTruePositive : ScanLabel::kMismatch;
}

ScanLabel LabelIfNotSimilar(std::size_t i, const GroundTruth& truth) {
    return truth.Overlapping(i) ? ScanLabel::kFalseNegative : ScanLabel::kTrueNegative;
}

void CheckMatches(std::span<const BestMatch> matches, const GroundTruth& truth) {
    if (matches.size() != truth.size()) {
        throw core::ConfigError("per-scan evaluation: " + std::to_string(matches.size()) +
                                " best matches for a ground truth of " +
                                std::to_string(truth.size()) + " scans");
    }
    for (std::size_t i = 0; i < matches.size(); ++i) {
        const BestMatch& m = matches[i];
        const std::string scan = "per-scan evaluation: scan " + std::to_string(i);
        if (std::isnan(m.distance)) throw core::ConfigError(scan + ": distance is NaN");
        if (m.match == kNoScan) {
            if (m.distance != std::numeric_limits<double>::infinity()) {
                throw core::ConfigError(scan + ": no match but a finite distance");
            }
        } else if (m.match >= truth.size() || !truth.Comparable(i, m.match)) {
            throw core::ConfigError(scan + ": match " + std::to_string(m.match) +
                                    " is not a scan outside the minimum gap");
        }
    }
}

std::size_t& Slot(TaxonomyCounts& counts, ScanLabel label) {
    switch (label) {
        case ScanLabel::kTruePositive:
            return counts.true_positive;
        case ScanLabel::kMismatch:
            return counts.mismatch;
        case ScanLabel::kFalsePositive:
            return counts.false_positive;
        case ScanLabel::kTrueNegative:
            return counts.true_negative;
        case ScanLabel::kFalseNegative:
            break;
    }
    return counts.false_negative;
}

constexpr auto kScanLabelNames = std::to_array<core::EnumName<ScanLabel>>({
    {ScanLabel::kTruePositive, "true_positive"},
    {ScanLabel::kMismatch, "mismatch"},
    {ScanLabel::kFalsePositive, "false_positive"},
    {ScanLabel::kTrueNegative, "true_negative"},
    {ScanLabel::kFalseNegative, "false_negative"},
});
static_assert(core::IsOneToOne(kScanLabelNames));

}  // namespace

std::string ToString(ScanLabel label) { return std::string(core::NameOf(kScanLabelNames, label)); }

double TaxonomyCounts::Recall() const { return detail::Ratio(true_positive, Overlapping()); }

double TaxonomyCounts::FalsePositiveRate() const {
    return detail::Ratio(false_positive, NonOverlapping());
}

std::vector<BestMatch> BestMatchesFromCondensed(std::span<const float> condensed,
                                                const GroundTruth& truth) {
    const std::size_t n = truth.size();
    if (condensed.size() != CondensedSize(n)) {
        throw core::ConfigError("per-scan evaluation: the distance matrix holds " +
                                std::to_string(condensed.size()) + " pairs, the ground truth of " +
                                std::to_string(n) + " scans needs " +
                                std::to_string(CondensedSize(n)));
    }
    std::vector<BestMatch> best(n);
    // Offer (i, j) to both scans; j ascending per i and i ascending overall, so strict
    // comparisons leave ties with the smaller index.
    const auto offer = [](BestMatch& m, std::size_t other, double distance) {
        if (distance < m.distance) {
            m.second_distance = m.distance;
            m.distance = distance;
            m.match = other;
        } else {
            m.second_distance = std::min(m.second_distance, distance);
        }
    };
    std::size_t at = 0;
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n; ++j, ++at) {
            if (!truth.Comparable(i, j)) continue;
            const double distance = condensed[at];
            if (std::isnan(distance)) {
                throw core::ConfigError("per-scan evaluation: distance of pair (" +
                                        std::to_string(i) + ", " + std::to_string(j) + ") is NaN");
            }
            offer(best[i], j, distance);
            offer(best[j], i, distance);
        }
    }
    return best;
}

std::vector<ScanLabel> LabelScans(std::span<const BestMatch> matches, const GroundTruth& truth,
                                  double t_d) {
    if (std::isnan(t_d)) throw core::ConfigError("per-scan evaluation: t_d must not be NaN");
    CheckMatches(matches, truth);
    std::vector<ScanLabel> labels(matches.size());
    for (std::size_t i = 0; i < matches.size(); ++i) {
        // Magnusson table I: similar when sigma'(S, S̄) < t_d.
        labels[i] = matches[i].distance < t_d ? LabelIfSimilar(i, matches[i], truth)
                                              : LabelIfNotSimilar(i, truth);
    }
    return labels;
}

TaxonomyCounts CountLabels(std::span<const ScanLabel> labels) {
    TaxonomyCounts counts;
    for (const ScanLabel label : labels) ++Slot(counts, label);
    return counts;
}

PerScanEvaluation EvaluatePerScan(std::span<const BestMatch> matches, const GroundTruth& truth,
                                  const PerScanConfig& config) {
    config.Validate();
    CheckMatches(matches, truth);
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < matches.size(); ++i) {
        if (matches[i].distance < inf) order.push_back(i);
    }
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return matches[a].distance < matches[b].distance;
    });

    PerScanEvaluation result;
    result.overlapping = truth.OverlappingCount();
    result.non_overlapping = truth.size() - result.overlapping;
    TaxonomyCounts counts;
    counts.false_negative = result.overlapping;
    counts.true_negative = result.non_overlapping;
    bool error_seen = false;
    for (std::size_t k = 0; k < order.size();) {
        const double t_d = matches[order[k]].distance;
        result.curve.push_back({t_d, counts});
        std::size_t end = k;
        for (; end < order.size() && matches[order[end]].distance == t_d; ++end) {
            const ScanLabel label = LabelIfSimilar(order[end], matches[order[end]], truth);
            const bool error = label == ScanLabel::kFalsePositive ||
                               (config.mismatches_are_errors && label == ScanLabel::kMismatch);
            if (error && !error_seen) {
                error_seen = true;
                result.zero_error.t_d = t_d;
                result.zero_error.counts = counts;
            }
        }
        for (; k < end; ++k) {
            const ScanLabel label = LabelIfSimilar(order[k], matches[order[k]], truth);
            --Slot(counts, LabelIfNotSimilar(order[k], truth));
            ++Slot(counts, label);
            if (!error_seen && label == ScanLabel::kTruePositive) {
                result.zero_error.last_true_positive_distance = t_d;
            }
        }
    }
    result.curve.push_back({inf, counts});
    if (!error_seen) result.zero_error.counts = counts;
    result.zero_error.recall = result.zero_error.counts.Recall();
    return result;
}

}  // namespace lidarloop::eval

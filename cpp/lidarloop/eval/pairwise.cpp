#include "lidarloop/eval/pairwise.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/detail/sweep.hpp"

namespace lidarloop::eval {
namespace {

using detail::CurveThinner;
using detail::IsScored;
using detail::KeepBest;
using detail::MakePoint;

struct Scored {
    float distance;
    bool loop;
};

void CheckDistance(const ScoredPair& pair) {
    if (std::isnan(pair.distance)) {
        throw core::ConfigError("pair-wise evaluation: distance of pair " +
                                detail::PairName(pair.i, pair.j) + " is NaN");
    }
}

void CheckThreshold(double threshold) {
    if (std::isnan(threshold)) throw core::ConfigError("evaluation threshold must not be NaN");
}

bool DetectedAt(float distance, double threshold) {
    return IsScored(distance) && static_cast<double>(distance) <= threshold;
}

// Distance and label of every pair, distance ascending; throws for a NaN distance.
std::vector<Scored> SortByDistance(std::span<const ScoredPair> pairs) {
    std::vector<Scored> sorted(pairs.size());
    for (std::size_t k = 0; k < pairs.size(); ++k) {
        CheckDistance(pairs[k]);
        sorted[k] = {pairs[k].distance, pairs[k].loop};
    }
    std::sort(sorted.begin(), sorted.end(),
              [](const Scored& a, const Scored& b) { return a.distance < b.distance; });
    return sorted;
}

// The curve, AUC and optima over the scored pairs `sorted` (ascending, no +inf). result's pair
// counts must be set and include the unscored pairs, which stay undetected at every point.
void Sweep(std::span<const Scored> sorted, const PairwiseConfig& config,
           PairwiseEvaluation& result) {
    Confusion c{0, 0, result.negatives, result.positives};
    CurvePoint previous = MakePoint(-std::numeric_limits<double>::infinity(), c);
    result.curve.push_back(previous);
    // Without a scored pair the best detector is the start point: nothing detected.
    result.best_mcc = {previous.threshold, Mcc(c), c};
    result.best_f1 = {previous.threshold, F1(c), c};
    CurveThinner thinner(config.max_curve_points);
    detail::AreaSum area;
    bool have_mcc = false;
    bool have_f1 = false;
    for (std::size_t k = 0; k < sorted.size();) {
        const float distance = sorted[k].distance;
        for (; k < sorted.size() && sorted[k].distance == distance; ++k) {
            ++(sorted[k].loop ? c.tp : c.fp);
            --(sorted[k].loop ? c.fn : c.tn);
        }
        const CurvePoint point = MakePoint(distance, c);
        ++result.distinct_thresholds;
        area.Step(c.fp - previous.confusion.fp, previous.confusion.tp, c.tp);
        KeepBest(result.best_mcc, have_mcc, Mcc(c), distance, c);
        KeepBest(result.best_f1, have_f1, F1(c), distance, c);
        if (k == sorted.size() || thinner.Keep(point)) result.curve.push_back(point);
        previous = point;
    }
    if (result.positives > 0 && result.negatives > 0)
        result.roc_auc = area.Area(result.positives, result.negatives);
}

// Position of the first of the ascending thresholds >= distance (their count when none is).
std::size_t FirstAtLeast(const std::vector<double>& ascending, float distance) {
    return static_cast<std::size_t>(
        std::lower_bound(ascending.begin(), ascending.end(), static_cast<double>(distance)) -
        ascending.begin());
}

}  // namespace

std::size_t CondensedSize(std::size_t n) { return n < 2 ? 0 : n * (n - 1) / 2; }

std::size_t CondensedIndex(std::size_t n, std::size_t i, std::size_t j) {
    return i * (2 * n - i - 1) / 2 + (j - i - 1);
}

void PairwiseConfig::Validate() const {
    if (max_curve_points != 0 && max_curve_points < 3) {
        throw core::ConfigError("pairwise.max_curve_points must be 0 (keep all) or >= 3, got " +
                                std::to_string(max_curve_points));
    }
}

std::vector<ScoredPair> CollectPairs(std::span<const float> condensed, const GroundTruth& truth) {
    const std::size_t n = truth.size();
    if (condensed.size() != CondensedSize(n)) {
        throw core::ConfigError("pair-wise evaluation: the distance matrix holds " +
                                std::to_string(condensed.size()) + " pairs, the ground truth of " +
                                std::to_string(n) + " scans needs " +
                                std::to_string(CondensedSize(n)));
    }
    if (n > std::numeric_limits<std::uint32_t>::max()) {
        throw core::ConfigError("pair-wise evaluation: more than 2^32 scans");
    }
    std::vector<ScoredPair> pairs;
    pairs.reserve(truth.ComparablePairCount());
    std::size_t at = 0;
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n; ++j, ++at) {
            if (!truth.Comparable(i, j)) continue;
            const float distance = condensed[at];
            if (std::isnan(distance)) {
                throw core::ConfigError("pair-wise evaluation: distance of pair " +
                                        detail::PairName(i, j) + " is NaN");
            }
            pairs.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j), distance,
                             truth.IsLoop(i, j)});
        }
    }
    return pairs;
}

PairwiseEvaluation EvaluatePairs(std::span<const ScoredPair> pairs, const PairwiseConfig& config) {
    config.Validate();
    if (pairs.empty()) throw core::EmptyInputError("pair-wise evaluation: no pairs to evaluate");
    const std::vector<Scored> sorted = SortByDistance(pairs);
    PairwiseEvaluation result;
    result.pairs = sorted.size();
    result.positives = static_cast<std::uint64_t>(
        std::count_if(sorted.begin(), sorted.end(), [](const Scored& s) { return s.loop; }));
    result.negatives = result.pairs - result.positives;
    // +inf sorts last: the sweep stops before the unscored pairs, which stay undetected.
    const auto scored = std::partition_point(sorted.begin(), sorted.end(),
                                             [](const Scored& s) { return IsScored(s.distance); });
    Sweep(std::span<const Scored>(sorted.begin(), scored), config, result);
    return result;
}

Confusion ConfusionAt(std::span<const ScoredPair> pairs, double threshold) {
    CheckThreshold(threshold);
    Confusion c;
    for (const auto& pair : pairs) {
        CheckDistance(pair);
        const bool detected = DetectedAt(pair.distance, threshold);
        if (pair.loop) {
            ++(detected ? c.tp : c.fn);
        } else {
            ++(detected ? c.fp : c.tn);
        }
    }
    return c;
}

std::vector<Confusion> ConfusionsAt(std::span<const ScoredPair> pairs,
                                    std::span<const double> thresholds) {
    for (const double threshold : thresholds) CheckThreshold(threshold);
    // order[r] is the position in `thresholds` of the r-th smallest threshold.
    std::vector<std::size_t> order(thresholds.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return thresholds[a] < thresholds[b]; });
    std::vector<double> ascending(thresholds.size());
    for (std::size_t r = 0; r < order.size(); ++r) ascending[r] = thresholds[order[r]];
    // A pair is detected from the first (ascending) threshold >= its distance on; an unscored
    // pair from none (slot T is never summed).
    std::vector<std::uint64_t> loops_from(thresholds.size() + 1, 0);
    std::vector<std::uint64_t> others_from(thresholds.size() + 1, 0);
    std::uint64_t loops = 0;
    for (const auto& pair : pairs) {
        CheckDistance(pair);
        const std::size_t first =
            IsScored(pair.distance) ? FirstAtLeast(ascending, pair.distance) : thresholds.size();
        ++(pair.loop ? loops_from : others_from)[first];
        loops += pair.loop ? 1 : 0;
    }
    const std::uint64_t others = pairs.size() - loops;
    std::vector<Confusion> result(thresholds.size());
    std::uint64_t tp = 0;
    std::uint64_t fp = 0;
    for (std::size_t r = 0; r < order.size(); ++r) {
        tp += loops_from[r];
        fp += others_from[r];
        result[order[r]] = {tp, fp, others - fp, loops - tp};
    }
    return result;
}

}  // namespace lidarloop::eval

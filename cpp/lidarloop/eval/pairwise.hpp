#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "lidarloop/eval/ground_truth.hpp"
#include "lidarloop/eval/metrics.hpp"

namespace lidarloop::eval {

/// Number of entries of the condensed upper triangle of an n x n distance matrix: n(n-1)/2.
std::size_t CondensedSize(std::size_t n);
/// Position of the pair i < j < n in the condensed upper triangle (row-major: (0,1), (0,2), ...,
/// (1,2), ...), the layout of pipeline::SimilarityMatrix::condensed().
std::size_t CondensedIndex(std::size_t n, std::size_t i, std::size_t j);

/// One evaluated scan pair of the pair-wise protocol (Röhling IV-B): scans i < j, their
/// descriptor distance and whether the ground truth calls them the same place. The distance is
/// W or sigma', or +inf for a pair that was never scored (a scan could not be read, or a results
/// file leaves the pair out): such a pair is never detected, at any threshold, +inf included.
/// 16 bytes, so that millions of pairs stay cheap.
struct ScoredPair {
    std::uint32_t i = 0;
    std::uint32_t j = 0;
    float distance = 0.0f;
    bool loop = false;
};

/// The pairs to evaluate from a full condensed distance matrix: every pair i < j that
/// truth.Comparable(i, j) accepts (pairs inside the minimum gap are skipped), labelled by
/// truth.IsLoop. `condensed` must hold CondensedSize(truth.size()) entries; throws
/// core::ConfigError otherwise or when a distance is NaN. O(n^2). Thread-safe.
std::vector<ScoredPair> CollectPairs(std::span<const float> condensed, const GroundTruth& truth);

/// Options of EvaluatePairs.
struct PairwiseConfig {
    /// Most points kept in PairwiseEvaluation::curve, >= 3, or 0 to keep one point per distinct
    /// threshold. Thinning keeps points evenly spaced along the ROC curve (by FPR + TPR), always
    /// with the first and the last; the AUC and the optima are computed on the full sweep.
    std::size_t max_curve_points = 1000;

    /// Throws core::ConfigError naming the invalid field (prefix "pairwise.").
    void Validate() const;
};

/// The classifier L_tau at one threshold: pairs with distance <= threshold are detected loops
/// (never a pair with distance +inf, see ScoredPair).
struct CurvePoint {
    double threshold = 0.0;  ///< tau; -inf for the start point (nothing detected)
    Confusion confusion;
    double tpr = 0.0;        ///< recall, the ROC y and the PR x
    double fpr = 0.0;        ///< the ROC x
    double precision = 0.0;  ///< the PR y (0 at the start point, see metrics.hpp)
};

/// The best threshold by one criterion, and what it gives.
struct BestThreshold {
    double threshold = 0.0;  ///< tau: a pair is a loop when distance <= tau
    double score = 0.0;      ///< the criterion's value (MCC or F1) at tau
    Confusion confusion;
};

/// Result of the threshold sweep over all pairs (Röhling IV-B/C, fig. 4).
struct PairwiseEvaluation {
    std::uint64_t pairs = 0;              ///< pairs evaluated
    std::uint64_t positives = 0;          ///< pairs that are loops
    std::uint64_t negatives = 0;          ///< pairs that are not
    std::size_t distinct_thresholds = 0;  ///< distinct finite distances: the swept thresholds
    /// ROC and precision-recall curve, threshold ascending (so FPR and TPR non-decreasing):
    /// the start point at -inf, then one point per distinct finite distance (possibly thinned).
    /// With unscored (+inf) pairs it ends short of (1, 1): they are never detected.
    std::vector<CurvePoint> curve;
    /// Area under the ROC curve by the trapezoid rule over every distinct threshold (ties are
    /// one diagonal step, i.e. they count half); nullopt without positives or negatives. The
    /// area stops where the curve does, so unscored pairs add none.
    std::optional<double> roc_auc;
    /// Thresholds maximising MCC and F1 over every distinct finite distance; on ties the
    /// smallest threshold (the most conservative detector) wins. Candidates are distances of
    /// pairs, so at least one pair is detected and the threshold is finite, unless no pair has
    /// a finite distance: then threshold -inf, nothing detected.
    BestThreshold best_mcc;
    BestThreshold best_f1;
};

/// Sweeps the threshold over all distinct finite distances of `pairs` in O(P log P) (one sort).
/// Throws core::EmptyInputError when `pairs` is empty and core::ConfigError when a distance is NaN.
/// Thread-safe.
PairwiseEvaluation EvaluatePairs(std::span<const ScoredPair> pairs,
                                 const PairwiseConfig& config = {});

/// The confusion of L_tau (distance <= threshold is a loop; +inf never is) on `pairs`, O(P).
/// Throws core::ConfigError for a NaN threshold or distance. Thread-safe.
Confusion ConfusionAt(std::span<const ScoredPair> pairs, double threshold);

/// ConfusionAt for several thresholds (Röhling table II), in the order given, in
/// O((P + T) log T). Throws core::ConfigError for a NaN threshold or distance. Thread-safe.
std::vector<Confusion> ConfusionsAt(std::span<const ScoredPair> pairs,
                                    std::span<const double> thresholds);

}  // namespace lidarloop::eval

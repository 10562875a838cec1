#pragma once

#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "lidarloop/eval/ground_truth.hpp"

namespace lidarloop::eval {

/// The most similar scan to one scan (Magnusson table I: S̄), among the scans outside the
/// minimum gap, and the second most similar one's distance.
struct BestMatch {
    /// S̄; kNoScan when no scan outside the gap has a finite distance to it (none was compared,
    /// or every pair is unscored, +inf, as the pairs a results file leaves out)
    std::size_t match = kNoScan;
    double distance = std::numeric_limits<double>::infinity();  ///< sigma'(S, S̄) or W
    /// The second smallest distance (any other scan outside the gap), for the distinctiveness
    /// ratio; +inf when there is none.
    double second_distance = std::numeric_limits<double>::infinity();
};

/// Per scan, its best match over all other scans outside the gap (offline, both directions, as
/// Magnusson compares every scan with all others except S_{i-S} .. S_{i+S}). `condensed` is the
/// upper triangle of the n x n distance matrix (see CondensedIndex). Ties go to the smaller scan
/// index. A scan whose pairs are all +inf gets no match, so it is never similar (a false or
/// true negative at every t_d), not a match to an arbitrary scan. Throws core::ConfigError when the
/// size does not match truth.size() or a distance is NaN.
/// O(n^2). Thread-safe.
std::vector<BestMatch> BestMatchesFromCondensed(std::span<const float> condensed,
                                                const GroundTruth& truth);

/// Magnusson table I. Given a scan S, Ŝ its nearest scan and S̄ its most similar scan (both
/// outside the minimum gap):
///   similar     = sigma'(S, S̄) < t_d
///   overlapping = the distance to Ŝ < t_r          (GroundTruth::Overlapping)
///   correct     = the distance to S̄ < t_r          (GroundTruth::IsLoop(S, S̄))
/// With a heading rule (Kvarntorp) "distance < t_r" also needs the headings to agree, for both
/// Ŝ and S̄.
enum class ScanLabel {
    kTruePositive,   ///< similar, overlapping, correct
    kMismatch,       ///< similar, overlapping, S̄ is not a place S overlaps with
    kFalsePositive,  ///< similar, not overlapping
    kTrueNegative,   ///< not similar, not overlapping
    kFalseNegative,  ///< not similar, overlapping
};

/// "true_positive", "mismatch", "false_positive", "true_negative", "false_negative".
std::string ToString(ScanLabel label);

/// Numbers of scans per label.
struct TaxonomyCounts {
    std::size_t true_positive = 0;
    std::size_t mismatch = 0;
    std::size_t false_positive = 0;
    std::size_t true_negative = 0;
    std::size_t false_negative = 0;

    /// Magnusson table II "pos.": TP + mismatch + FN.
    std::size_t Overlapping() const { return true_positive + mismatch + false_negative; }
    /// Table II "neg.": FP + TN.
    std::size_t NonOverlapping() const { return false_positive + true_negative; }
    /// Table II "true pos.": TP / overlapping scans (0 when there are none).
    double Recall() const;
    /// Table II "false pos.": FP / non-overlapping scans (0 when there are none).
    double FalsePositiveRate() const;
    friend bool operator==(const TaxonomyCounts&, const TaxonomyCounts&) = default;
};

/// Labels every scan by table I for the difference threshold `t_d` (similar: distance < t_d;
/// t_d may be +inf). `matches[i]` must be scan i's best match: truth.size() entries, each match
/// kNoScan (never similar) or a scan outside the gap; throws core::ConfigError otherwise or for a
/// NaN t_d or distance. O(n log degree). Thread-safe.
std::vector<ScanLabel> LabelScans(std::span<const BestMatch> matches, const GroundTruth& truth,
                                  double t_d);

TaxonomyCounts CountLabels(std::span<const ScanLabel> labels);

/// Options of EvaluatePerScan.
struct PerScanConfig {
    /// Whether a mismatch is an error for the zero-error operating point. Magnusson II-E
    /// speaks of "the obtainable recall rate without false positives or mismatches" and table
    /// II reports no mismatches, so the default counts them; false reproduces a literal
    /// reading of "the maximum number of true positives without any false positives".
    bool mismatches_are_errors = true;

    void Validate() const {}
};

/// Table I counts at one difference threshold (one abscissa of Magnusson fig. 1).
struct TaxonomyPoint {
    double t_d = 0.0;
    TaxonomyCounts counts;
};

/// The largest t_d without errors (Magnusson III-B: "the maximum number of true positives
/// without any false positives", marked by a bar in fig. 1).
struct ZeroErrorPoint {
    /// The largest such t_d: the smallest distance of a scan that would be an error (FP, or
    /// mismatch when those count); +inf when no scan can become one. Any t_d in
    /// (last_true_positive_distance, t_d] gives the same labels.
    double t_d = std::numeric_limits<double>::infinity();
    /// Largest distance among the true positives there (-inf when there are none).
    double last_true_positive_distance = -std::numeric_limits<double>::infinity();
    TaxonomyCounts counts;  ///< the labels at t_d
    double recall = 0.0;    ///< counts.Recall(): TP / overlapping scans
};

/// Result of the per-scan evaluation.
struct PerScanEvaluation {
    std::size_t overlapping = 0;      ///< scans with a positive partner (table II "pos.")
    std::size_t non_overlapping = 0;  ///< the others (table II "neg.")
    /// Counts against t_d (fig. 1): one point at each distinct finite distance (the scans with
    /// smaller distances are similar), then one at +inf; t_d ascending.
    std::vector<TaxonomyPoint> curve;
    ZeroErrorPoint zero_error;
};

/// Sweeps t_d over every distinct distance in O(n log n) and finds the zero-error point.
/// Same input rules as LabelScans. Thread-safe.
PerScanEvaluation EvaluatePerScan(std::span<const BestMatch> matches, const GroundTruth& truth,
                                  const PerScanConfig& config = {});

}  // namespace lidarloop::eval

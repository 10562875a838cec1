#pragma once

#include <cstdint>

namespace lidarloop::eval {

/// A binary confusion matrix: counts of pairs (or scans) by truth and decision.
struct Confusion {
    std::uint64_t tp = 0;  ///< loop, detected
    std::uint64_t fp = 0;  ///< no loop, detected
    std::uint64_t tn = 0;  ///< no loop, not detected
    std::uint64_t fn = 0;  ///< loop, not detected

    std::uint64_t Positives() const { return tp + fn; }
    std::uint64_t Negatives() const { return tn + fp; }
    std::uint64_t PredictedPositives() const { return tp + fp; }
    std::uint64_t Total() const { return tp + fp + tn + fn; }
    friend bool operator==(const Confusion&, const Confusion&) = default;
};

// Convention for zero denominators (all five functions): a rate whose denominator is 0 has no
// evidence for it and is 0, the `zero_division=0` convention of scikit-learn. In particular
// Precision is 0 when nothing is detected, Recall is 0 when there are no loops, F1 is 0 when
// tp = fp = fn = 0 (only true negatives), and MCC is 0 whenever one of its four factors is 0
// (no loops, no non-loops, nothing detected or everything detected): such a matrix carries no
// correlation between truth and decision. Every function is O(1) and thread-safe.

/// TP / (TP + FP), in [0, 1]; 0 when nothing is detected.
double Precision(const Confusion& c);
/// TP / (TP + FN), the true-positive rate, in [0, 1]; 0 when there are no loops.
double Recall(const Confusion& c);
/// FP / (FP + TN), in [0, 1]; 0 when there are no non-loops.
double FalsePositiveRate(const Confusion& c);
/// Röhling eq. (9): 2 TP / (2 TP + FN + FP), in [0, 1]; 0 when tp = fp = fn = 0.
double F1(const Confusion& c);
/// Röhling eq. (10), the Matthews correlation coefficient
/// (TP TN - FP FN) / sqrt((TP + FP)(TP + FN)(TN + FP)(TN + FN)), in [-1, 1]; 0 when a factor
/// of the denominator is 0. Computed in double (exact enough for counts up to ~1e15).
double Mcc(const Confusion& c);

}  // namespace lidarloop::eval

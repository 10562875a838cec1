#pragma once

// Pieces of the threshold sweep shared by EvaluatePairs (all pairs in memory) and
// StreamedPairwise (pairs streamed), so that both produce the same curve, AUC and optima.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "lidarloop/eval/metrics.hpp"
#include "lidarloop/eval/pairwise.hpp"

namespace lidarloop::eval::detail {

// +inf marks a pair that was never scored: a scan that could not be read, or a pair a results
// file leaves out. No threshold, not even +inf, detects it; otherwise the sweep would end at
// +inf calling every pair a loop, and a learnt threshold could be +inf.
inline bool IsScored(float distance) { return distance != std::numeric_limits<float>::infinity(); }

// "(i, j)", for errors about a pair.
inline std::string PairName(std::size_t i, std::size_t j) {
    return "(" + std::to_string(i) + ", " + std::to_string(j) + ")";
}

inline CurvePoint MakePoint(double threshold, const Confusion& c) {
    return {threshold, c, Recall(c), FalsePositiveRate(c), Precision(c)};
}

// Keeps curve points evenly spaced along the ROC curve, measured by FPR + TPR (its L1 length,
// since the curve is monotone), so the steep low-FPR part is not lost between the many points
// of the flat part.
class CurveThinner {
public:
    explicit CurveThinner(std::size_t max_points)
        : step_(max_points == 0 ? 0.0 : 2.0 / static_cast<double>(max_points - 2)) {}

    /// The bucket of a point; non-decreasing along the curve.
    double Bucket(const CurvePoint& point) const {
        return std::floor((point.fpr + point.tpr) / step_);
    }
    double last_bucket() const { return last_bucket_; }

    bool Keep(const CurvePoint& point) {
        if (step_ == 0.0) return true;
        const double bucket = Bucket(point);
        if (bucket <= last_bucket_) return false;
        last_bucket_ = bucket;
        return true;
    }

private:
    double step_;
    double last_bucket_ = 0.0;
};

inline void KeepBest(BestThreshold& best, bool& have, double score, double threshold,
                     const Confusion& c) {
    // Strictly greater: ties keep the smaller threshold seen first.
    if (!have || score > best.score) {
        best = {threshold, score, c};
        have = true;
    }
}

// The ROC area as an exact integer: twice the area times positives times negatives, summed
// step by step (FP grows by delta_fp while TP goes from tp_before to tp_after). Integer sums do
// not depend on how the steps are grouped, so both evaluations give the same double.
__extension__ typedef unsigned __int128 UInt128;

class AreaSum {
public:
    void Step(std::uint64_t delta_fp, std::uint64_t tp_before, std::uint64_t tp_after) {
        sum_ += static_cast<UInt128>(delta_fp) * (tp_before + tp_after);
    }
    double Area(std::uint64_t positives, std::uint64_t negatives) const {
        return static_cast<double>(
            static_cast<long double>(sum_) /
            (2.0L * static_cast<long double>(positives) * static_cast<long double>(negatives)));
    }

private:
    UInt128 sum_ = 0;
};

}  // namespace lidarloop::eval::detail

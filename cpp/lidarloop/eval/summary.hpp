#pragma once

#include <cstddef>
#include <optional>
#include <span>

#include "lidarloop/eval/per_scan.hpp"

namespace lidarloop::eval {

/// Distribution summary of a set of values (distances, ratios, run times).
struct Summary {
    std::size_t count = 0;
    double mean = 0.0;
    double min = 0.0;
    double p05 = 0.0;  ///< 5 % quantile
    double p25 = 0.0;
    double median = 0.0;
    double p75 = 0.0;
    double p95 = 0.0;
    double max = 0.0;
};

/// The q-quantile (q in [0, 1]) of ascending `sorted` values by linear interpolation between
/// order statistics (Hyndman & Fan type 7, the default of R and NumPy). Throws
/// core::EmptyInputError for no values and core::Error for q outside [0, 1]. O(1).
double Quantile(std::span<const double> sorted, double q);

/// Summary of `values`, which must be finite. Throws core::EmptyInputError for no values and
/// core::Error for a non-finite value. O(n log n). Thread-safe.
Summary Summarize(std::span<const double> values);

/// How distinct each scan's best match is: best / second-best distance per scan (Lowe's ratio;
/// near 0 = one clear candidate, 1 = a tie). The second best is the runner-up among all scans
/// outside the gap, which on a slow sequence is often a neighbour of the best match.
struct DistinctivenessSummary {
    std::size_t scans = 0;         ///< scans given
    std::size_t used = 0;          ///< scans with a best and a second-best distance
    std::optional<Summary> ratio;  ///< nullopt when no scan has a ratio
};

/// Ratios from BestMatch::distance / BestMatch::second_distance; scans without a finite second
/// distance are skipped, and 0 / 0 counts as 1 (two identical candidates). Thread-safe.
DistinctivenessSummary SummarizeDistinctiveness(std::span<const BestMatch> matches);

}  // namespace lidarloop::eval

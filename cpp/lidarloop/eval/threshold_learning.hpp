#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "lidarloop/eval/metrics.hpp"
#include "lidarloop/eval/pairwise.hpp"

namespace lidarloop::eval {

/// What a learnt threshold maximises.
enum class Criterion { kMcc, kF1 };

std::string ToString(Criterion criterion);
/// Parses "mcc" / "f1"; throws core::ConfigError listing the valid names.
Criterion ParseCriterion(std::string_view name);

/// A threshold learnt on training pairs and applied to test pairs (one row of Röhling table I:
/// optimal tau, F1 and MCC).
struct ThresholdTransfer {
    Criterion criterion = Criterion::kMcc;
    double threshold = 0.0;    ///< tau learnt on the training pairs (distance <= tau is a loop)
    double train_score = 0.0;  ///< the criterion's value on the training pairs at tau
    Confusion train;           ///< at tau, training pairs
    Confusion test;            ///< at tau, test pairs
    double test_f1 = 0.0;      ///< Röhling eq. (9) on the test pairs
    double test_mcc = 0.0;     ///< Röhling eq. (10) on the test pairs
};

/// The row of a threshold learnt by `criterion` (`learnt`: its tau, score and training
/// confusion) with its confusion `test` on the test pairs.
ThresholdTransfer TransferOf(Criterion criterion, const BestThreshold& learnt,
                             const Confusion& test);

/// Learns tau on `train` (exact optimum of `criterion` over every distinct finite distance, ties
/// to the smallest tau, see EvaluatePairs) and evaluates it on `test`; tau is always finite. The
/// two sets may come from the same sequence (SplitByQuery) or from different data sets. Throws
/// core::EmptyInputError when either is empty or no training pair has a finite distance.
/// O(P log P). Thread-safe.
ThresholdTransfer LearnAndTest(std::span<const ScoredPair> train, std::span<const ScoredPair> test,
                               Criterion criterion);

/// Pairs split into a training and a test part.
struct PairSplit {
    std::size_t first_test_scan = 0;
    std::vector<ScoredPair> train;  ///< pairs whose later scan j < first_test_scan
    std::vector<ScoredPair> test;   ///< pairs whose later scan j >= first_test_scan
};

/// Splits by the later scan of each pair, the query of an online detector: the training part
/// is everything a detector could have seen before scan first_test_scan, the test part all
/// queries from then on (against the whole past, training scans included). Every pair lands in
/// exactly one part. O(P). Thread-safe.
PairSplit SplitByQuery(std::span<const ScoredPair> pairs, std::size_t first_test_scan);

/// Learning a threshold on the first part of a sequence.
struct ThresholdLearningConfig {
    /// Fraction of the scans whose queries form the training part, in (0, 1); the test part
    /// starts at scan round(train_fraction * n).
    double train_fraction = 0.5;
    Criterion criterion = Criterion::kMcc;

    /// Throws core::ConfigError naming the invalid field (prefix "threshold_learning.").
    void Validate() const;
};

/// SplitByQuery at round(train_fraction * scan_count), then LearnAndTest. Throws
/// core::ConfigError for an invalid config and core::EmptyInputError when a part has no pairs
/// or the training part no finite distance.
ThresholdTransfer LearnOnFirstPart(std::span<const ScoredPair> pairs, std::size_t scan_count,
                                   const ThresholdLearningConfig& config);

}  // namespace lidarloop::eval

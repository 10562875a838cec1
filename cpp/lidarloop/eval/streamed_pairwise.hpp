#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "lidarloop/eval/ground_truth.hpp"
#include "lidarloop/eval/pairwise.hpp"
#include "lidarloop/eval/per_scan.hpp"
#include "lidarloop/eval/threshold_learning.hpp"

namespace lidarloop::eval {

/// Distance of scans i < j as the evaluation stores it (float; +inf: never scored). May be
/// called concurrently.
using PairDistance = std::function<float(std::size_t i, std::size_t j)>;

/// The distances of the loop pairs of `truth` (the positives of the pair-wise protocol), in the
/// order of GroundTruth::ForEachLoop: O(P) calls of `distance`, 4 bytes a pair. Throws
/// core::ConfigError for a NaN distance. Thread-safe.
std::vector<float> ScorePositives(const GroundTruth& truth, const PairDistance& distance);

/// What StreamedPairwise computes besides the sweep over all pairs.
struct StreamedRequest {
    /// Must keep at most max_curve_points (0, every point, would need every distance).
    PairwiseConfig pairwise;
    std::vector<double> thresholds;  ///< the confusion of all pairs at each (table II, defaults)
    std::optional<ThresholdLearningConfig> learning;  ///< learn on the first part, when given
};

/// The figures of the pair-wise and per-scan protocols, equal to those of the pairs in memory.
struct StreamedResult {
    PairwiseEvaluation pairwise;           ///< EvaluatePairs(pairs, request.pairwise)
    std::vector<Confusion> at_thresholds;  ///< ConfusionsAt(pairs, request.thresholds)
    /// LearnOnFirstPart(pairs, n, *request.learning); nullopt without learning or where that
    /// throws core::EmptyInputError (a part without pairs or without a finite distance).
    std::optional<ThresholdTransfer> learnt;
    std::vector<BestMatch> best_matches;  ///< BestMatchesFromCondensed
    /// False only when the best MCC is <= 0 at every threshold of a positive pair's distance, on
    /// both sides: then a threshold between two positives' distances, which the streamed sweep
    /// does not visit, could score higher (docs/evaluation.md, "Evaluation in linear memory").
    bool optimum_exact = true;
};

/// The pair-wise evaluation (Röhling IV-B/C), threshold learning on the first part, fixed
/// thresholds and the per-scan best matches of every comparable pair of a sequence, in memory
/// O(n + positives) instead of the O(n^2) pairs: the positives are kept, the negatives are
/// counted as they stream past. Results equal EvaluatePairs(CollectPairs(...)) and friends
/// exactly (same doubles), with the caveat of StreamedResult::optimum_exact.
///
/// Use: construct with the positives (ScorePositives), then stream every pair i < j twice: for
/// each pass, give each thread a NewSink(), Add every pair to some sink, Merge every sink, then
/// EndPass(). After the second pass, Result(). The exact curve needs the second pass: its
/// thinned points between two positives' distances are order statistics of the negatives.
/// Memory: per distinct finite positive distance 13 bytes (its key, a one-byte count, two 4-byte
/// slots of negatives), again for the training part's, and two bucket tables of 4 MiB; while
/// constructing, the positives' distances (4 bytes each, sorted in place); per sink 24 bytes a scan
/// and up to 7 MiB of batch; in the second pass 32 KiB per located curve point and sink; and a
/// bitmap of the distinct distances (512 MiB of address space, of which only the pages of occurring
/// distances become resident: 4 KiB per 32768 consecutive float values; first pass only). Sinks
/// sort their batches and locate them among the slots on their own, and add them to shared
/// counters under a mutex.
class StreamedPairwise {
    struct Context;          // fixed before the first pass: the request, the positives' levels
    struct FirstPassResult;  // what the first pass found, moved whole into the second
    class FirstPass;         // counts the negatives in slots and coarse buckets
    class FirstSink;
    class SecondPass;  // counts the negatives near the wanted ranks; computes the result
    class SecondSink;

public:
    /// Per-thread accumulator of the pass that made it; cheap to Add to, not thread-safe itself.
    /// Move-only.
    class Sink {
    public:
        Sink(Sink&&) noexcept;
        Sink& operator=(Sink&&) noexcept;
        ~Sink();
        /// One pair i < j and its distance; pairs the ground truth does not compare are
        /// ignored. Throws core::ConfigError for a NaN distance.
        void Add(std::size_t i, std::size_t j, float distance);

    private:
        friend class StreamedPairwise;
        Sink(std::unique_ptr<FirstSink> first, std::unique_ptr<SecondSink> second);
        std::unique_ptr<FirstSink> first_;    ///< a sink of the first pass, or
        std::unique_ptr<SecondSink> second_;  ///< of the second
    };

    /// `positives`: ScorePositives(truth, distance), one per truth.loop_count. Throws
    /// core::ConfigError for an invalid request, a NaN threshold or positive
    /// distance, a count of positives other than truth.loop_count, more than 2^32 scans, or
    /// fewer than 2 scans (no pair). `truth` must outlive this.
    StreamedPairwise(const GroundTruth& truth, std::vector<float> positives,
                     StreamedRequest request);
    ~StreamedPairwise();
    StreamedPairwise(const StreamedPairwise&) = delete;
    StreamedPairwise& operator=(const StreamedPairwise&) = delete;

    /// 1 or 2 while pairs are streamed, 3 when Result() is ready.
    int pass() const;
    /// Both passes are done: Result() is ready (stream while this is false).
    bool finished() const { return pass() > 2; }
    /// A sink of the current pass; core::Error when both have ended.
    Sink NewSink() const;
    /// Adds a sink's counts (after counting what it still holds); core::Error for a sink of
    /// another pass. Not thread-safe.
    void Merge(Sink& sink);
    /// Ends a pass. Throws core::EmptyInputError after the first when there is no pair.
    void EndPass();
    /// After the second pass.
    StreamedResult Result() const;

private:
    std::unique_ptr<const Context> context_;
    std::unique_ptr<FirstPass> first_;    ///< during the first pass
    std::unique_ptr<SecondPass> second_;  ///< from its end on
    bool finished_ = false;
};

/// Streams every pair i < j of `n` scans through `evaluation` serially, both passes, and returns
/// the result: the reference for parallel drivers and for tests.
StreamedResult StreamSerially(StreamedPairwise& evaluation, std::size_t n,
                              const PairDistance& distance);

}  // namespace lidarloop::eval

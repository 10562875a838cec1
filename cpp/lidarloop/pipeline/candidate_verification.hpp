#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <unordered_map>
#include <vector>

#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/pipeline/progress_counter.hpp"
#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/prepared_scan.hpp"

namespace lidarloop::pipeline {

class NeighbourOverlaps;

/// Times of one verification run, seconds.
struct VerificationTimes {
    std::vector<double> pair_seconds;   ///< per registered candidate pair (coarse search + ICP)
    std::vector<double> query_seconds;  ///< per query: its coarse search images (shared by pairs)
    /// The same steps in CPU seconds of the thread that ran them (what they cost on one core).
    std::vector<double> pair_cpu_seconds;
    std::vector<double> query_cpu_seconds;

    /// Adds `other`'s times after these.
    void Append(const VerificationTimes& other);
};

/// Verifications already computed, by (query, match) scan pair: runs over the same prepared scans
/// with the same VerificationConfig and LoopCheck (e.g. the methods of one evaluation, whose top-k
/// candidates overlap) register each pair once. Verify is deterministic, so a cached verdict equals
/// a fresh one. Thread-safe.
class VerificationCache {
public:
    std::optional<registration::Verification> Find(std::size_t query, std::size_t match) const;
    void Store(std::size_t query, std::size_t match, const registration::Verification& verdict);
    std::size_t size() const;

private:
    static std::uint64_t Key(std::size_t query, std::size_t match);

    mutable std::mutex mutex_;
    std::unordered_map<std::uint64_t, registration::Verification> verdicts_;
};

/// Registers the candidates of `query` to it (registration::Verify) and fills
/// query.verifications and query.accepted. `query_scan` is the query prepared with
/// detector.verification.reduction, `match_of(j)` candidate j prepared the same way (called once
/// per registered candidate, e.g. to expand a CompactPreparedScan; an empty PreparedScan, e.g.
/// of a skipped scan, is rejected as kTooFewPoints). A candidate whose
/// distance fails an explicitly set detector.threshold is not registered (reason kPruned).
/// Appends to `times` when given (pairs found in `cache` are not timed); takes verdicts from and
/// adds them to `cache` when given. The candidates are registered in parallel unless told
/// otherwise (`match_of` is then called from worker threads); the verdicts do not depend on it.
/// `check`, when given, runs on the verified query, and a candidate it rules out whatever its
/// pose (LoopCheck::MayClose: the odometry puts the two scans farther apart than a loop's
/// max_loop_distance_m plus its gate) is not registered (reason kOdometryMismatch). With
/// detector.stop_at_first_loop the candidates are registered one after another in rank order until
/// one is accepted and stays so after `check`; after that only those `more` still wants are
/// registered (none when `more` is empty), the others get kNotNeeded (pruned ones stay kPruned).
void VerifyQuery(LoopQuery& query, const registration::PreparedScan& query_scan,
                 const std::function<registration::PreparedScan(std::size_t)>& match_of,
                 const DetectorConfig& detector, const core::Method& method,
                 VerificationTimes* times = nullptr, VerificationCache* cache = nullptr,
                 Execution execution = Execution::kParallel, const LoopCheck& check = {},
                 const MoreLoopsWanted& more = {});

/// VerifyQuery for every query that has candidates (in parallel unless told otherwise);
/// `scans[i]` is scan i prepared, kept compact (each expanded when verified; the pair times
/// include expanding the candidate). `progress(done, total)` is called from worker threads, one
/// call at a time with `done` rising. Once every query is verified, `check.judge_revisits` (where
/// given) judges their loops together within detector.verification.acceptance.revisit_path_m.
/// `neighbours`: the registrations of each scan alone to the one before, for the neighbour and
/// motion rules, where `scans` are submaps (PosesFromNeighbours); null: made from `scans`.
VerificationTimes VerifyQueries(std::vector<LoopQuery>& queries,
                                const std::vector<registration::CompactPreparedScan>& scans,
                                const DetectorConfig& detector, const core::Method& method,
                                Execution execution = Execution::kParallel,
                                const ProgressReport& progress = {},
                                VerificationCache* cache = nullptr, const LoopCheck& check = {},
                                const MoreLoopsWanted& more = {},
                                NeighbourOverlaps* neighbours = nullptr);

}  // namespace lidarloop::pipeline

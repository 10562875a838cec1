#pragma once

#include <cstddef>
#include <functional>
#include <mutex>
#include <optional>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"

#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/registration/prepared_scan.hpp"
#include "lidarloop/registration/verification_config.hpp"

namespace lidarloop::pipeline {

/// What each scan of a sequence shows with its neighbour: the distinctive overlap
/// (registration::Overlap::MinDistinctive) of scan i registered to scan i - 1 (scan 1 to scan 0
/// for both), as registration::Verify registers a candidate. It is the overlap a revisit of the
/// same place can show at this density, field of view and step, the reference of
/// AcceptanceConfig::min_neighbour_overlap_ratio (docs/verification.md, "What the neighbours
/// show"). Computed when first asked for, once per scan; thread-safe. The same registration
/// gives the step between the two scans, which the motion rule chains (MotionRulesOutLoop).
class NeighbourOverlaps {
public:
    /// A scan registered to the one before it.
    struct Pair {
        /// registration::Overlap::MinDistinctive when the pair is accepted, else NaN.
        double distinctive_overlap;
        /// The later scan in the earlier one's frame when registered (any verdict), else none.
        std::optional<core::Transform> T_earlier_later;
    };

    /// `prepared_of(i)`: scan i prepared as the candidates are (an empty PreparedScan for a
    /// skipped scan), for i < `count_of()` (the scans so far: a sequence only grows); called for
    /// a scan and its neighbour when Of first needs them, from the asking thread. What they refer
    /// to must outlive this object.
    NeighbourOverlaps(std::function<registration::PreparedScan(std::size_t)> prepared_of,
                      std::function<std::size_t()> count_of,
                      const registration::VerificationConfig& config);

    /// The distinctive overlap of scan `scan` with its neighbour; NaN when the pair is not
    /// accepted (a skipped scan, a turn the coarse search missed) or not there yet: no
    /// reference, no rule.
    double Of(std::size_t scan);

    /// Scan `scan` (>= 1) in the frame of scan `scan` - 1 (T_{scan-1}_{scan}), from the same
    /// registration as Of; none for scan 0, a pair ICP did not register, or one not there yet.
    std::optional<core::Transform> StepOf(std::size_t scan);

    /// The first scan of the chain that ends at `scan`: the smallest s <= scan such that every
    /// scan from s + 1 to `scan` has a step (StepOf); `scan` itself for one not there yet.
    /// Registers the steps it walks back over until a known chain or a missing step; remembered, so
    /// a whole sequence costs one walk.
    std::size_t ChainStart(std::size_t scan);

    /// `later` registered to `earlier` as Of registers a scan to its neighbour: a scan not
    /// stored in the sequence yet, e.g. an online query with the last stored scan.
    static Pair Between(const registration::PreparedScan& later,
                        const registration::PreparedScan& earlier,
                        const registration::VerificationConfig& config);

    /// How many neighbour pairs Of and StepOf have registered.
    std::size_t registered() const;

private:
    std::function<registration::PreparedScan(std::size_t)> prepared_of_;
    std::function<std::size_t()> count_of_;
    registration::VerificationConfig config_;
    // The pair of `later` and the scan before it, registered once; a copy, since another thread
    // may grow the cache.
    Pair PairOf(std::size_t later);

    mutable std::mutex mutex_;
    std::vector<Pair> known_;  ///< by neighbour pair (its later scan); valid where computed
    std::vector<bool> computed_;
    std::vector<std::size_t> chain_start_;  ///< by scan; kUnknownChainStart where not walked
};

/// Every scan's pose from the scans alone, where no odometry places submaps (offline, when every
/// scan exists): scan i is scan i - 1's pose times their step where `neighbours` accepts the pair
/// (Of finite: an accepted registration is right to centimetres), else it starts a new piece at
/// the identity. Each pose's path_m runs along the accepted steps and jumps by more than `window_m`
/// between pieces, so that a submap window of `window_m` never joins two pieces
/// (docs/verification.md, "Submaps without odometry"). Registers every pair of the `count` scans
/// (in parallel with kParallel), which the neighbour and motion rules then find cached.
std::vector<core::StampedPose> PosesFromNeighbours(NeighbourOverlaps& neighbours, std::size_t count,
                                                   double window_m, Execution execution);

/// The candidate search's check where PosesFromNeighbours (`chained`) placed the submaps: two
/// scans at most twice `window_m` apart along the chained steps may not close a loop. Their
/// submaps could share scans, and a registration would find the shared points; they are the
/// recent past of one piece, not a revisit. Scans of different pieces are never that close.
LoopCheck SubmapsApart(const std::vector<core::StampedPose>& chained, double window_m);

/// Scan i in the frame of scan i - 1 (NeighbourOverlaps::StepOf): none where unknown.
using StepOf = std::function<std::optional<core::Transform>(std::size_t scan)>;

/// The first scan of the chain of steps that ends at a scan (NeighbourOverlaps::ChainStart).
using ChainStartOf = std::function<std::size_t(std::size_t scan)>;

/// Whether the scans from `match` to `query` (match < query), chained by their steps, rule out a
/// loop between the two: they do when the chain puts the query farther from the match than
/// max_loop_distance_m + motion_drift_m + motion_drift_ratio times the chain's path, and never
/// turns more than acceptance.motion_max_turn_deg from the match's heading (180, the default:
/// any chain) (docs/verification.md, "The scans' own motion"). False when the rule is off (0
/// degrees), match >= query, or a step is unknown; a chain that turns past the bound is left at
/// that turn, so it registers the steps up to there only, once (they are cached).
bool MotionRulesOutLoop(std::size_t query, std::size_t match, const StepOf& step_of,
                        const registration::AcceptanceConfig& config);

/// Rejects (RejectReason::kUnlikeMotion) each accepted verification of a query that
/// MotionRulesOutLoop rules out, and chooses the query's loop again among the rest. Empty when
/// the rule is off. The check rejects only, as CheckAgainstNeighbours.
LoopCheck CheckAgainstMotion(StepOf step_of, const registration::AcceptanceConfig& config);

/// Rejects (RejectReason::kUnlikeNeighbours) each accepted verification of a query whose
/// distinctive overlap is under `min_ratio` times the lower of what its two scans show with
/// their neighbours (`reference_of(scan)`, e.g. NeighbourOverlaps::Of; a scan whose reference is
/// NaN does not judge), and chooses the query's loop again among the rest. Asks for a reference
/// only where it may decide (a loop overlapping `min_ratio` or more never: a reference is at most
/// 1; the match's only when the query's alone would reject). Empty when `min_ratio` is 0. The
/// check rejects only: the candidates are searched, ordered and registered as without it.
LoopCheck CheckAgainstNeighbours(std::function<double(std::size_t)> reference_of, double min_ratio);

/// What judges a sequence's verified loops: `given` where it judges (non-empty: the odometry's
/// check), else, with no knowledge besides the scans, CheckAgainstNeighbours with `reference_of`
/// (e.g. NeighbourOverlaps::Of) at config.acceptance.min_neighbour_overlap_ratio, then, given
/// `step_of` (e.g. NeighbourOverlaps::StepOf; offline: VerifyQueries), CheckAgainstMotion, which
/// judges the pairs a chain joins (LoopCheck::motion_judges, given `chain_start_of`, e.g.
/// NeighbourOverlaps::ChainStart, and every chain judged: motion_max_turn_deg 180); with
/// `given`'s yaw_window (the layouts', LayoutOrderOf).
LoopCheck JudgeOf(const LoopCheck& given, std::function<double(std::size_t)> reference_of,
                  StepOf step_of, const registration::VerificationConfig& config,
                  ChainStartOf chain_start_of = {});

}  // namespace lidarloop::pipeline

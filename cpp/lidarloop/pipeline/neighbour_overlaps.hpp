#pragma once

#include <cstddef>
#include <functional>
#include <mutex>
#include <vector>

#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/registration/prepared_scan.hpp"
#include "lidarloop/registration/verification_config.hpp"

namespace lidarloop::pipeline {

/// What each scan of a sequence shows with its neighbour: the distinctive overlap
/// (registration::Overlap::MinDistinctive) of scan i registered to scan i - 1 (scan 1 to scan 0
/// for both), as registration::Verify registers a candidate. It is the overlap a revisit of the
/// same place can show at this density, field of view and step, the reference of
/// AcceptanceConfig::min_neighbour_overlap_ratio (docs/verification.md, "What the neighbours
/// show"). Computed when first asked for, once per scan; thread-safe.
class NeighbourOverlaps {
public:
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

    /// What `later` shows with `earlier` (registered as Of registers a scan to its neighbour):
    /// a scan not stored in the sequence yet, e.g. an online query with the last stored scan.
    static double Between(const registration::PreparedScan& later,
                          const registration::PreparedScan& earlier,
                          const registration::VerificationConfig& config);

    /// How many neighbour pairs Of has registered.
    std::size_t registered() const;

private:
    std::function<registration::PreparedScan(std::size_t)> prepared_of_;
    std::function<std::size_t()> count_of_;
    registration::VerificationConfig config_;
    mutable std::mutex mutex_;
    std::vector<double> known_;  ///< by neighbour pair (its later scan); NaN where not computed
    std::vector<bool> computed_;
};

/// Rejects (RejectReason::kUnlikeNeighbours) each accepted verification of a query whose
/// distinctive overlap is under `min_ratio` times the lower of what its two scans show with
/// their neighbours (`reference_of(scan)`, e.g. NeighbourOverlaps::Of; a scan whose reference is
/// NaN does not judge), and chooses the query's loop again among the rest. Asks for a reference
/// only where it may decide (a loop overlapping `min_ratio` or more never: a reference is at most
/// 1; the match's only when the query's alone would reject). Empty when `min_ratio` is 0. The
/// check rejects only: the candidates are searched, ordered and registered as without it.
LoopCheck CheckAgainstNeighbours(std::function<double(std::size_t)> reference_of, double min_ratio);

/// What judges a sequence's verified loops: `odometry` where given (non-empty), else, with no
/// knowledge besides the scans, CheckAgainstNeighbours with `reference_of` (e.g.
/// NeighbourOverlaps::Of) at config.acceptance.min_neighbour_overlap_ratio.
LoopCheck JudgeOf(const LoopCheck& odometry, std::function<double(std::size_t)> reference_of,
                  const registration::VerificationConfig& config);

}  // namespace lidarloop::pipeline

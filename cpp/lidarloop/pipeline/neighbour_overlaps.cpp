#include "lidarloop/pipeline/neighbour_overlaps.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "lidarloop/registration/coarse_alignment.hpp"
#include "lidarloop/registration/verification.hpp"

namespace lidarloop::pipeline {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

}  // namespace

double NeighbourOverlaps::Between(const registration::PreparedScan& later,
                                  const registration::PreparedScan& earlier,
                                  const registration::VerificationConfig& config) {
    if (!later.structure || !earlier.structure) return kNan;
    const registration::CoarseQuery coarse(*later.structure, config.coarse);
    const registration::Verification verdict = registration::Verify(later, coarse, earlier, config);
    return verdict.accepted ? verdict.overlap.MinDistinctive() : kNan;
}

NeighbourOverlaps::NeighbourOverlaps(
    std::function<registration::PreparedScan(std::size_t)> prepared_of,
    std::function<std::size_t()> count_of, const registration::VerificationConfig& config)
    : prepared_of_(std::move(prepared_of)), count_of_(std::move(count_of)), config_(config) {}

double NeighbourOverlaps::Of(std::size_t scan) {
    const std::size_t later = std::max<std::size_t>(scan, 1);  // scan 0's neighbour pair is 1 -> 0
    if (later >= count_of_()) return kNan;                     // not there yet: nothing cached
    {
        const std::lock_guard lock(mutex_);
        if (later < computed_.size() && computed_[later]) return known_[later];
    }
    // Registered outside the lock: two threads asking at once compute the same value.
    const double overlap = Between(prepared_of_(later), prepared_of_(later - 1), config_);
    const std::lock_guard lock(mutex_);
    if (later >= computed_.size()) {
        computed_.resize(later + 1, false);
        known_.resize(later + 1, kNan);
    }
    if (!computed_[later]) {
        computed_[later] = true;
        known_[later] = overlap;
    }
    return known_[later];
}

std::size_t NeighbourOverlaps::registered() const {
    const std::lock_guard lock(mutex_);
    return static_cast<std::size_t>(std::count(computed_.begin(), computed_.end(), true));
}

namespace {

// Whether a loop overlapping `distinctive_overlap` is under `min_ratio` times the lower reference
// of its scans. A reference is at most 1, so a loop at or over min_ratio needs none; the query's
// is asked for first, and the match's only when the query's alone would reject it (the lower
// one only lowers the bar).
bool UnlikeNeighbours(double distinctive_overlap, double min_ratio,
                      const std::function<double()>& query_reference,
                      const std::function<double()>& match_reference) {
    if (!(distinctive_overlap < min_ratio)) return false;
    const double query = query_reference();
    if (!std::isnan(query) && !(distinctive_overlap < min_ratio * query)) return false;
    // std::fmin ignores a NaN: a scan without a reference does not judge.
    return distinctive_overlap < min_ratio * std::fmin(query, match_reference());
}

}  // namespace

LoopCheck CheckAgainstNeighbours(std::function<double(std::size_t)> reference_of,
                                 double min_ratio) {
    LoopCheck check;
    if (!(min_ratio > 0.0)) return check;
    check.reject = [reference_of = std::move(reference_of), min_ratio](LoopQuery& query) {
        for (std::size_t c = 0; c < query.verifications.size(); ++c) {
            registration::Verification& verdict = query.verifications[c];
            if (!verdict.accepted) continue;
            const std::size_t match = query.candidates[c].index;
            if (!UnlikeNeighbours(
                    verdict.overlap.MinDistinctive(), min_ratio,
                    [&] { return reference_of(query.query); }, [&] { return reference_of(match); }))
                continue;
            verdict.accepted = false;
            verdict.reason = registration::RejectReason::kUnlikeNeighbours;
        }
        query.accepted = query.loop().has_value();
    };
    return check;
}

LoopCheck JudgeOf(const LoopCheck& odometry, std::function<double(std::size_t)> reference_of,
                  const registration::VerificationConfig& config) {
    if (odometry) return odometry;
    return CheckAgainstNeighbours(std::move(reference_of),
                                  config.acceptance.min_neighbour_overlap_ratio);
}

}  // namespace lidarloop::pipeline

#include "lidarloop/pipeline/neighbour_overlaps.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <tbb/parallel_for.h>

#include "lidarloop/core/angles.hpp"
#include "lidarloop/registration/coarse_alignment.hpp"
#include "lidarloop/registration/verification.hpp"

namespace lidarloop::pipeline {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kUnknownChainStart = std::numeric_limits<std::size_t>::max();

}  // namespace

NeighbourOverlaps::Pair NeighbourOverlaps::Between(const registration::PreparedScan& later,
                                                   const registration::PreparedScan& earlier,
                                                   const registration::VerificationConfig& config) {
    if (!later.structure || !earlier.structure) return {kNan, std::nullopt};
    const registration::CoarseQuery coarse(*later.structure, config.coarse);
    const registration::Verification verdict = registration::Verify(later, coarse, earlier, config);
    Pair pair{verdict.accepted ? verdict.overlap.MinDistinctive() : kNan, std::nullopt};
    if (verdict.Registered()) pair.T_earlier_later = verdict.T_match_query;
    return pair;
}

NeighbourOverlaps::NeighbourOverlaps(
    std::function<registration::PreparedScan(std::size_t)> prepared_of,
    std::function<std::size_t()> count_of, const registration::VerificationConfig& config)
    : prepared_of_(std::move(prepared_of)), count_of_(std::move(count_of)), config_(config) {}

double NeighbourOverlaps::Of(std::size_t scan) {
    const std::size_t later = std::max<std::size_t>(scan, 1);  // scan 0's neighbour pair is 1 -> 0
    if (later >= count_of_()) return kNan;                     // not there yet: nothing cached
    return PairOf(later).distinctive_overlap;
}

std::optional<core::Transform> NeighbourOverlaps::StepOf(std::size_t scan) {
    if (scan == 0 || scan >= count_of_()) return std::nullopt;
    return PairOf(scan).T_earlier_later;
}

std::size_t NeighbourOverlaps::ChainStart(std::size_t scan) {
    if (scan >= count_of_()) return scan;  // not there yet: nothing remembered
    std::vector<std::size_t> walked;       // scans whose chain starts where the walk ends
    std::size_t start = scan;
    for (;;) {
        {
            const std::lock_guard lock(mutex_);
            if (start < chain_start_.size() && chain_start_[start] != kUnknownChainStart) {
                start = chain_start_[start];
                break;
            }
        }
        walked.push_back(start);
        if (start == 0 || !StepOf(start)) break;
        --start;
    }
    const std::lock_guard lock(mutex_);
    if (scan >= chain_start_.size()) chain_start_.resize(scan + 1, kUnknownChainStart);
    for (const std::size_t s : walked) chain_start_[s] = start;
    return start;
}

NeighbourOverlaps::Pair NeighbourOverlaps::PairOf(std::size_t later) {
    {
        const std::lock_guard lock(mutex_);
        if (later < computed_.size() && computed_[later]) return known_[later];
    }
    // Registered outside the lock: two threads asking at once compute the same value.
    Pair pair = Between(prepared_of_(later), prepared_of_(later - 1), config_);
    const std::lock_guard lock(mutex_);
    if (later >= computed_.size()) {
        computed_.resize(later + 1, false);
        known_.resize(later + 1, Pair{kNan, std::nullopt});
    }
    if (!computed_[later]) {
        computed_[later] = true;
        known_[later] = std::move(pair);
    }
    return known_[later];
}

std::size_t NeighbourOverlaps::registered() const {
    const std::lock_guard lock(mutex_);
    return static_cast<std::size_t>(std::count(computed_.begin(), computed_.end(), true));
}

std::vector<core::StampedPose> PosesFromNeighbours(NeighbourOverlaps& neighbours, std::size_t count,
                                                   double window_m, Execution execution) {
    const auto register_pair = [&neighbours](std::size_t later) { neighbours.Of(later); };
    if (execution == Execution::kParallel) {
        tbb::parallel_for(std::size_t{1}, std::max<std::size_t>(count, 1), register_pair);
    } else {
        for (std::size_t later = 1; later < count; ++later) register_pair(later);
    }
    // Twice the window and a metre: no window reaches across a piece's end.
    const double break_m = 2.0 * window_m + 1.0;
    std::vector<core::StampedPose> poses(count);
    core::Transform T_world_scan = core::Transform::Identity();
    double path_m = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
        if (i > 0) {
            const std::optional<core::Transform> step = neighbours.StepOf(i);
            if (step && std::isfinite(neighbours.Of(i))) {
                T_world_scan = T_world_scan * *step;
                path_m += step->translation().norm();
            } else {
                T_world_scan = core::Transform::Identity();
                path_m += break_m;
            }
        }
        poses[i].T_world_sensor = T_world_scan;
        poses[i].path_m = path_m;
    }
    return poses;
}

LoopCheck SubmapsApart(const std::vector<core::StampedPose>& chained, double window_m) {
    std::vector<double> path_m(chained.size());
    for (std::size_t i = 0; i < chained.size(); ++i) path_m[i] = chained[i].path_m.value_or(kNan);
    const auto apart = [path_m = std::move(path_m), reach_m = 2.0 * window_m](
                           std::size_t query, std::size_t match, double /*max_loop_distance_m*/) {
        if (query >= path_m.size() || match >= path_m.size()) return true;
        return !(std::abs(path_m[query] - path_m[match]) <= reach_m);
    };
    LoopCheck check;
    check.may_close = apart;
    check.in_reach_bound = apart;
    return check;
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

// Rejects, for `reason`, each accepted verification of `query` for whose candidate `rejects(c)`
// holds, then chooses the query's loop again among the rest.
void RejectAcceptedWhere(LoopQuery& query, registration::RejectReason reason,
                         const std::function<bool(std::size_t candidate)>& rejects) {
    for (std::size_t c = 0; c < query.verifications.size(); ++c) {
        registration::Verification& verdict = query.verifications[c];
        if (!verdict.accepted || !rejects(c)) continue;
        verdict.accepted = false;
        verdict.reason = reason;
    }
    query.accepted = query.loop().has_value();
}

}  // namespace

LoopCheck CheckAgainstNeighbours(std::function<double(std::size_t)> reference_of,
                                 double min_ratio) {
    LoopCheck check;
    if (!(min_ratio > 0.0)) return check;
    check.reject = [reference_of = std::move(reference_of), min_ratio](LoopQuery& query) {
        RejectAcceptedWhere(
            query, registration::RejectReason::kUnlikeNeighbours, [&](std::size_t c) {
                const std::size_t match = query.candidates[c].index;
                return UnlikeNeighbours(
                    query.verifications[c].overlap.MinDistinctive(), min_ratio,
                    [&] { return reference_of(query.query); }, [&] { return reference_of(match); });
            });
    };
    return check;
}

bool MotionRulesOutLoop(std::size_t query, std::size_t match, const StepOf& step_of,
                        const registration::AcceptanceConfig& config) {
    if (!(config.motion_max_turn_deg > 0.0) || match >= query) return false;
    const double max_turn_rad = config.motion_max_turn_deg * core::kRadiansPerDegree;
    // At 180 degrees (the default) no heading exceeds the bound: skip an atan2 per step.
    const bool heading_bounded = config.motion_max_turn_deg < 180.0;
    core::Transform T_match_scan = core::Transform::Identity();
    double path_m = 0.0;
    for (std::size_t scan = match + 1; scan <= query; ++scan) {
        const std::optional<core::Transform> step = step_of(scan);
        if (!step) return false;
        T_match_scan = T_match_scan * *step;
        path_m += step->translation().norm();
        if (!heading_bounded) continue;
        const Eigen::Matrix3d& R = T_match_scan.linear();
        if (std::abs(std::atan2(R(1, 0), R(0, 0))) > max_turn_rad) return false;  // it turned
    }
    return T_match_scan.translation().norm() >
           config.max_loop_distance_m + config.motion_drift_m + config.motion_drift_ratio * path_m;
}

LoopCheck CheckAgainstMotion(StepOf step_of, const registration::AcceptanceConfig& config) {
    LoopCheck check;
    if (!(config.motion_max_turn_deg > 0.0)) return check;
    check.reject = [step_of = std::move(step_of), config](LoopQuery& query) {
        RejectAcceptedWhere(query, registration::RejectReason::kUnlikeMotion, [&](std::size_t c) {
            return MotionRulesOutLoop(query.query, query.candidates[c].index, step_of, config);
        });
    };
    return check;
}

LoopCheck JudgeOf(const LoopCheck& given, std::function<double(std::size_t)> reference_of,
                  StepOf step_of, const registration::VerificationConfig& config,
                  ChainStartOf chain_start_of) {
    if (given) return given;
    LoopCheck neighbours = CheckAgainstNeighbours(std::move(reference_of),
                                                  config.acceptance.min_neighbour_overlap_ratio);
    LoopCheck motion =
        step_of ? CheckAgainstMotion(std::move(step_of), config.acceptance) : LoopCheck{};
    // With a turn bound the rule leaves chains that turn past it unjudged: no pair is sure to be.
    const bool motion_judges =
        motion && chain_start_of && config.acceptance.motion_max_turn_deg >= 180.0;
    LoopCheck judge;
    if (!motion) {
        judge = std::move(neighbours);
    } else if (!neighbours) {
        judge = std::move(motion);
    } else {
        judge.reject = [neighbours = std::move(neighbours),
                        motion = std::move(motion)](LoopQuery& q) {
            neighbours(q);
            motion(q);
        };
    }
    if (motion_judges) {
        judge.motion_judges = [chain_start_of = std::move(chain_start_of)](std::size_t query,
                                                                           std::size_t match) {
            return match < query && chain_start_of(query) <= match;
        };
    }
    judge.yaw_window = given.yaw_window;  // the layouts' (LayoutOrderOf), where given
    return judge;
}

}  // namespace lidarloop::pipeline

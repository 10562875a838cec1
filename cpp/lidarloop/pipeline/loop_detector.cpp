#include "lidarloop/pipeline/loop_detector.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <tuple>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "lidarloop/core/angles.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/pipeline/candidate_verification.hpp"
#include "lidarloop/pipeline/neighbour_overlaps.hpp"

namespace lidarloop::pipeline {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
// The odometry pose of a scan that has none (a loaded map's): the gate cannot judge it.
const Eigen::Matrix4d kUnknownPose = Eigen::Matrix4d::Constant(kNan);

double SecondRatio(double best, double second) {
    if (second == 0.0) return 1.0;
    return best / second;
}

// Fills second_ratio and accepted from the candidates and a search for the best candidate
// outside the gap around the best match. `along`: the scans' positions in the gap's unit
// (MinGap::Along); empty when unknown (a gap in metres without a path), which leaves
// second_ratio NaN.
void Finish(LoopQuery& result, const core::MinGap& gap, const std::vector<double>& along,
            const DescriptorMethod& method, double threshold,
            const std::function<std::vector<Neighbor>(const std::function<bool(std::size_t)>&)>&
                search_one) {
    if (!result.has_match()) return;
    const Neighbor best = result.candidates.front();
    result.accepted = method.IsMatch(best.distance, threshold);
    if (gap.unit != core::MinGap::Unit::kScans && along.empty()) return;
    const auto other_place = [&](std::size_t j) {
        return gap.Allows(best.index, j, along[best.index], along[j]);
    };
    const std::vector<Neighbor> second = search_one(other_place);
    if (!second.empty()) result.second_ratio = SecondRatio(best.distance, second.front().distance);
}

// Validates an offline detection and returns its threshold.
double CheckOfflineDetection(const DetectorConfig& detector, const core::Method& method,
                             const std::vector<double>& times_s, const std::vector<double>& path_m,
                             std::size_t scans) {
    detector.Validate();
    const double threshold = detector.ThresholdFor(method);
    MethodOf(method).ValidateThreshold(threshold);
    if (times_s.size() != scans) {
        throw core::ConfigError("offline detection: " + std::to_string(times_s.size()) +
                                " times for " + std::to_string(scans) + " scans");
    }
    if (!path_m.empty() && path_m.size() != scans) {
        throw core::ConfigError("offline detection: " + std::to_string(path_m.size()) +
                                " path lengths for " + std::to_string(scans) + " scans");
    }
    if (detector.min_gap.unit == core::MinGap::Unit::kMetres && path_m.size() != scans) {
        throw core::ConfigError(
            "detection.min_gap_unit is metres, which needs the path length "
            "of every scan: got " +
            std::to_string(path_m.size()) + " for " + std::to_string(scans) + " scans");
    }
    return threshold;
}

using Filter = std::function<bool(std::size_t)>;
// The `count` best scans `filter` admits, by (distance, index), with the distances the matrix
// holds (rounded to float).
using CandidateSearch = std::function<std::vector<Neighbor>(std::size_t count, const Filter&)>;

// The scans the odometry lets a query close a loop with: `exact` (LoopCheck::MayClose) and a
// cheap `bound` of it (LoopCheck::in_reach_bound); each empty where the check has none.
struct Reach {
    Filter exact;
    Filter bound;
};

// search(count, eligible && reach.exact), asking `search` for growing lists and judging them in
// rank order: `exact` costs far more than the gap, so it judges only the scans that rank high
// enough to matter. `bound` goes into the search's own filter: a query with few scans in reach
// (most that have no loop) would otherwise rank the whole run, 39 ms at 36,000 scans
// (bench_pipeline BM_QueryDeep). A ranking by (distance, index) is a total order, so a longer
// list starts with the shorter one.
std::vector<Neighbor> SearchReachable(const CandidateSearch& search, std::size_t count,
                                      const Filter& eligible, const Reach& reach) {
    const Filter searched =
        reach.bound ? Filter([&](std::size_t j) { return eligible(j) && reach.bound(j); })
                    : eligible;
    if (!reach.exact) return search(count, searched);
    std::vector<Neighbor> kept;
    std::size_t judged = 0;
    for (std::size_t asked = count;; asked *= 2) {
        const std::vector<Neighbor> found = search(asked, searched);
        for (; judged < found.size() && kept.size() < count; ++judged) {
            if (reach.exact(found[judged].index)) kept.push_back(found[judged]);
        }
        if (kept.size() == count || found.size() < asked) return kept;
    }
}

// The scans `check` lets query scan `i` close a loop with (empty: all).
Reach ReachFrom(std::size_t i, const LoopCheck& check, const DetectorConfig& detector) {
    Reach reach;
    const double max_loop_distance_m = detector.verification.acceptance.max_loop_distance_m;
    if (check.may_close) {
        reach.exact = [i, &check, max_loop_distance_m](std::size_t j) {
            return check.may_close(i, j, max_loop_distance_m);
        };
    }
    if (check.in_reach_bound) {
        reach.bound = [i, &check, max_loop_distance_m](std::size_t j) {
            return check.in_reach_bound(i, j, max_loop_distance_m);
        };
    }
    return reach;
}

// How a query's shortlist is ordered before its top_k are taken.
enum class ShortlistOrder { kRank, kNearestView, kMostAlikeLayout };

ShortlistOrder OrderOf(const DetectorConfig& detector, const LoopCheck& check) {
    if (check.view_distance_m) return ShortlistOrder::kNearestView;
    if (check.layout_similarity && detector.layout_shortlist > 0)
        return ShortlistOrder::kMostAlikeLayout;
    return ShortlistOrder::kRank;
}

// How many best-ranked scans a query's top_k are taken from: odometry_shortlist where `check`
// orders them by the odometry's view distance, layout_shortlist where by their layouts, else
// top_k.
std::size_t ShortlistSize(const DetectorConfig& detector, const LoopCheck& check) {
    switch (OrderOf(detector, check)) {
        case ShortlistOrder::kNearestView:
            return static_cast<std::size_t>(std::max(detector.top_k, detector.odometry_shortlist));
        case ShortlistOrder::kMostAlikeLayout:
            return static_cast<std::size_t>(std::max(detector.top_k, detector.layout_shortlist));
        case ShortlistOrder::kRank:
            break;
    }
    return static_cast<std::size_t>(detector.top_k);
}

// Per candidate, the key `check` orders the shortlist by, smallest first: the view distance, or
// the layout similarity negated; a scan it cannot judge (NaN) last.
std::vector<double> OrderKeys(const LoopQuery& result, const LoopCheck& check,
                              ShortlistOrder order) {
    std::vector<double> keys;
    keys.reserve(result.candidates.size());
    for (const Neighbor& c : result.candidates) {
        const double key = order == ShortlistOrder::kNearestView
                               ? check.view_distance_m(result.query, c.index)
                               : -check.layout_similarity(result.query, c.index);
        keys.push_back(std::isnan(key) ? std::numeric_limits<double>::infinity() : key);
    }
    return keys;
}

// The top_k of `result`'s shortlist: where `check` knows the view distances, the nearest first;
// else where it knows the layouts, the most alike first (equal ones in rank order). Scans that
// fail an explicit threshold come last: verification prunes them, and from a longer shortlist
// they would push out scans it registers.
void OrderShortlist(LoopQuery& result, const LoopCheck& check, const DetectorConfig& detector,
                    const DescriptorMethod& method) {
    auto& candidates = result.candidates;
    const ShortlistOrder order = OrderOf(detector, check);
    if (order != ShortlistOrder::kRank) {
        const std::vector<double> keys = OrderKeys(result, check, order);
        std::vector<char> pruned(candidates.size(), 0);
        for (std::size_t k = 0; k < candidates.size() && detector.threshold; ++k)
            pruned[k] = !method.IsMatch(candidates[k].distance, *detector.threshold);
        std::vector<std::size_t> ranks(candidates.size());
        for (std::size_t k = 0; k < ranks.size(); ++k) ranks[k] = k;
        std::stable_sort(ranks.begin(), ranks.end(), [&](std::size_t a, std::size_t b) {
            return pruned[a] != pruned[b] ? pruned[a] < pruned[b] : keys[a] < keys[b];
        });
        // The top_k alone, without the shortlist's capacity: offline every scan's query is kept
        // (200 candidates held 3 kB a scan, 110 MB over 36,000 scans). In rank order the search
        // found top_k at most.
        const std::size_t kept = std::min(ranks.size(), static_cast<std::size_t>(detector.top_k));
        std::vector<Neighbor> ordered;
        ordered.reserve(kept);
        for (std::size_t k = 0; k < kept; ++k) ordered.push_back(candidates[ranks[k]]);
        candidates = std::move(ordered);
    }
}

// The candidates of query scan `query` among the scans `eligible` admits, offline (DetectOne)
// and online (LoopDetector::Search) alike: the shortlist within `check`'s reach, the decision and
// second_ratio (Finish; `along`: the scans' positions in the gap's unit, empty when unknown),
// then the top_k in the order `check` gives them (OrderShortlist).
LoopQuery RankCandidates(std::size_t query, const CandidateSearch& search, const Filter& eligible,
                         const std::vector<double>& along, const DetectorConfig& detector,
                         const DescriptorMethod& method, double threshold, const LoopCheck& check) {
    const Reach reach = ReachFrom(query, check, detector);
    LoopQuery result;
    result.query = query;
    result.candidates = SearchReachable(search, ShortlistSize(detector, check), eligible, reach);
    Finish(result, detector.min_gap, along, method, threshold, [&](const Filter& other_place) {
        return SearchReachable(
            search, 1, [&](std::size_t j) { return eligible(j) && other_place(j); }, reach);
    });
    OrderShortlist(result, check, detector, method);
    return result;
}

// Scan i's candidates among the scans j < i outside the gap (and the path rule, when `path_m` is
// known), as LoopDetector::Process gives them online.
LoopQuery DetectOne(std::size_t i, const CandidateSearch& search, const std::vector<double>& along,
                    const std::vector<double>& path_m, const DetectorConfig& detector,
                    const DescriptorMethod& method, double threshold, const LoopCheck& check) {
    const Filter eligible = [&](std::size_t j) {
        return j < i && detector.min_gap.Allows(i, j, along[i], along[j]) &&
               (path_m.empty() || detector.PathAllows(path_m[i], path_m[j]));
    };
    return RankCandidates(i, search, eligible, along, detector, method, threshold, check);
}

// Extra neighbours asked of the index, so that float ties at the k-th place can be seen.
constexpr std::size_t kIndexMargin = 4;

// The first `count` of `found` (the index's answer to `asked` neighbours, by double distance)
// by (float-rounded distance, index), as the matrix ranks them; nullopt when a scan the index
// did not return could tie in float with the last of them.
std::optional<std::vector<Neighbor>> RankedAsTheMatrix(std::vector<Neighbor> found,
                                                       std::size_t count, std::size_t asked) {
    for (Neighbor& n : found) n.distance = double{static_cast<float>(n.distance)};
    if (found.size() == asked && count > 0 && count < asked &&
        !(found[count - 1].distance < found.back().distance)) {
        return std::nullopt;
    }
    std::stable_sort(found.begin(), found.end(), [](const Neighbor& a, const Neighbor& b) {
        return a.distance < b.distance || (a.distance == b.distance && a.index < b.index);
    });
    if (found.size() > count) found.resize(count);
    return found;
}

}  // namespace

void DetectorConfig::Validate() const {
    min_gap.Validate("detection.min_gap");
    if (!(std::isfinite(min_path_m) && min_path_m >= 0.0)) {
        throw core::ConfigError("detection.min_path_m must be a finite number >= 0, got " +
                                std::to_string(min_path_m));
    }
    if (threshold && !(std::isfinite(*threshold) && *threshold >= 0.0)) {
        throw core::ConfigError("detection.threshold must be a finite number >= 0, got " +
                                core::NumberText(*threshold));
    }
    if (top_k < 1 || top_k > 1000) {
        throw core::ConfigError("detection.top_k must be in [1, 1000], got " +
                                std::to_string(top_k));
    }
    if (odometry_shortlist < 1 || odometry_shortlist > 1000) {
        throw core::ConfigError("detection.odometry_shortlist must be in [1, 1000], got " +
                                std::to_string(odometry_shortlist));
    }
    if (layout_shortlist < 0 || layout_shortlist > 1000) {
        throw core::ConfigError("detection.layout_shortlist must be in [0, 1000], got " +
                                std::to_string(layout_shortlist));
    }
    verification.Validate();
}

std::optional<std::size_t> LoopQuery::loop() const {
    if (!verified()) return accepted && has_match() ? std::optional<std::size_t>(0) : std::nullopt;
    // Of the accepted candidates the one that shares most of the view: the nearest, most
    // reliable constraint (docs/verification.md, "Which candidate is the loop").
    std::optional<std::size_t> best;
    for (std::size_t i = 0; i < verifications.size(); ++i) {
        if (!verifications[i].accepted) continue;
        if (!best || verifications[i].score() > verifications[*best].score()) best = i;
    }
    return best;
}

namespace {

// The odometry's relative pose of two scans and the path between them.
struct OdometryBetween {
    core::Transform T_match_query;
    double path_m = 0.0;
};

// Empty where the odometry does not know both scans' poses and path (finite): it cannot judge
// their loop.
std::optional<OdometryBetween> OdometryOfPair(
    std::size_t query, std::size_t match,
    const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of) {
    const OdometryBetween odometry{T_odom_sensor_of(match).inverse() * T_odom_sensor_of(query),
                                   std::abs(path_m_of(query) - path_m_of(match))};
    if (!odometry.T_match_query.matrix().allFinite() || !std::isfinite(odometry.path_m)) return {};
    return odometry;
}

// LoopCheck::in_reach_bound of the odometry: OdometryAllowsALoop tries the loop pose nearest to
// the odometry's (its rotation, its translation shortened to the loop's distance), whose
// discrepancy is a pure translation of the sensors' distance minus the loop's. A slack relative
// to the reach and to the coordinates (their difference rounds at their scale) keeps rounding
// from ruling out a scan OdometryAllowsALoop keeps; an allowance that is NaN rules out nothing.
bool MayBeInReach(std::size_t query, std::size_t match, double max_loop_distance_m,
                  const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
                  const std::function<double(std::size_t)>& path_m_of,
                  const std::function<double(double)>& translation_allowance_m) {
    constexpr double kRoundingSlack = 1e-9;
    const core::Transform T_odom_query = T_odom_sensor_of(query);
    const core::Transform T_odom_match = T_odom_sensor_of(match);
    const double path_m = std::abs(path_m_of(query) - path_m_of(match));
    // Where OdometryOfPair cannot judge the pair, neither can this.
    if (!T_odom_query.matrix().allFinite() || !T_odom_match.matrix().allFinite() ||
        !std::isfinite(path_m)) {
        return true;
    }
    const Eigen::Vector3d& query_m = T_odom_query.translation();
    const Eigen::Vector3d& match_m = T_odom_match.translation();
    const double reach_m = max_loop_distance_m + translation_allowance_m(path_m);
    const double slack_m = kRoundingSlack * (1.0 + reach_m + query_m.norm() + match_m.norm());
    return !((query_m - match_m).norm() > reach_m + slack_m);
}

// How much a registration of the query tells where the query is: a fit that passed every test
// of the fit itself (accepted, or rejected only for the sensors' distance) 1, one rejected for a
// rival pose half (either of its two poses may be the place), any other 0.
double FitVote(const registration::Verification& verdict) {
    if (verdict.accepted) return 1.0;
    if (!verdict.Registered()) return 0.0;
    if (verdict.reason == registration::RejectReason::kTooFar) return 1.0;
    if (verdict.reason == registration::RejectReason::kAmbiguous) return 0.5;
    return 0.0;
}

}  // namespace

registration::PoseAllowed OdometryAllowedPoses(
    std::size_t query, std::size_t match,
    const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of, const OdometryGate& gate) {
    const auto odometry = OdometryOfPair(query, match, T_odom_sensor_of, path_m_of);
    if (!odometry) return {};
    return [gate, odometry = *odometry](const core::Transform& T_match_query) {
        return !gate(T_match_query, odometry.T_match_query, odometry.path_m);
    };
}

registration::YawWindow OdometryYawWindow(
    std::size_t query, std::size_t match,
    const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of, const OdometryGate& gate) {
    const auto odometry = OdometryOfPair(query, match, T_odom_sensor_of, path_m_of);
    if (!odometry || !gate.rotation_allowance_deg) return {};
    const Eigen::Matrix3d R = odometry->T_match_query.linear();
    return {std::atan2(R(1, 0), R(0, 0)),
            gate.rotation_allowance_deg(odometry->path_m) * core::kRadiansPerDegree};
}

bool OdometryAllowsALoop(std::size_t query, std::size_t match, double max_loop_distance_m,
                         const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
                         const std::function<double(std::size_t)>& path_m_of,
                         const OdometryGate& gate) {
    const auto odometry = OdometryOfPair(query, match, T_odom_sensor_of, path_m_of);
    if (!odometry) return true;
    core::Transform nearest = odometry->T_match_query;
    const double distance_m = nearest.translation().norm();
    if (distance_m > max_loop_distance_m) nearest.translation() *= max_loop_distance_m / distance_m;
    return !gate(nearest, odometry->T_match_query, odometry->path_m);
}

void RejectLoopsUnlikeEarlierFits(
    LoopQuery& query, const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of, const OdometryGate& gate) {
    // A witness: an earlier fit with a vote whose pose the odometry's gate allows.
    const auto vote_of = [&](std::size_t c) {
        const registration::Verification& verdict = query.verifications[c];
        const double vote = FitVote(verdict);
        if (vote == 0.0) return 0.0;
        const registration::PoseAllowed allowed = OdometryAllowedPoses(
            query.query, query.candidates[c].index, T_odom_sensor_of, path_m_of, gate);
        return allowed && allowed(verdict.T_match_query) ? vote : 0.0;
    };
    // Not decided yet: neither accepted nor rejected (rank order, a candidate after a batch).
    const auto undecided = [&](std::size_t c) {
        const registration::Verification& verdict = query.verifications[c];
        return !verdict.accepted && verdict.reason == registration::RejectReason::kNone;
    };
    for (std::size_t c = 0; c < query.verifications.size(); ++c) {
        registration::Verification& verdict = query.verifications[c];
        if (!verdict.accepted) continue;
        // A verdict found before those ranked before it were decided (a cached one) is judged
        // when they are: its votes are theirs.
        bool earlier_decided = true;
        for (std::size_t earlier = 0; earlier < c; ++earlier)
            earlier_decided = earlier_decided && !undecided(earlier);
        if (!earlier_decided) continue;
        double agree = 1.0;  // the loop's own
        double disagree = 0.0;
        for (std::size_t earlier = 0; earlier < c; ++earlier) {
            const double vote = vote_of(earlier);
            if (vote == 0.0) continue;
            // The two fits put the two matches relative to each other; the odometry between
            // them must allow that as it allows a loop.
            const registration::PoseAllowed between =
                OdometryAllowedPoses(query.candidates[earlier].index, query.candidates[c].index,
                                     T_odom_sensor_of, path_m_of, gate);
            if (!between) continue;
            const core::Transform T_match_earlier =
                verdict.T_match_query * query.verifications[earlier].T_match_query.inverse();
            (between(T_match_earlier) ? agree : disagree) += vote;
        }
        if (agree > disagree) continue;
        verdict.accepted = false;
        verdict.reason = registration::RejectReason::kUnlikeFits;
    }
}

std::size_t RejectLoopsAgainstOdometry(
    LoopQuery& query, const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of, const OdometryGate& gate) {
    std::size_t rejected = 0;
    for (std::size_t c = 0; c < query.verifications.size(); ++c) {
        registration::Verification& verdict = query.verifications[c];
        if (!verdict.accepted) continue;
        const registration::PoseAllowed allowed = OdometryAllowedPoses(
            query.query, query.candidates[c].index, T_odom_sensor_of, path_m_of, gate);
        if (!allowed || allowed(verdict.T_match_query)) continue;
        verdict.accepted = false;
        verdict.reason = registration::RejectReason::kOdometryMismatch;
        ++rejected;
    }
    RejectLoopsUnlikeEarlierFits(query, T_odom_sensor_of, path_m_of, gate);
    query.accepted = query.loop().has_value();
    return rejected;
}

namespace {

// An accepted verification of a sequence, with what the odometry says of its two scans.
struct AcceptedLoop {
    std::size_t query_index = 0;  // in the queries
    std::size_t candidate = 0;    // in the query's candidates
    std::size_t query = 0;
    std::size_t match = 0;
    double query_path_m = 0.0;
    double match_path_m = 0.0;
};

std::vector<AcceptedLoop> AcceptedLoopsTheOdometryKnows(
    const std::vector<LoopQuery>& queries,
    const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of) {
    const auto known = [&](std::size_t scan) {
        return std::isfinite(path_m_of(scan)) && T_odom_sensor_of(scan).matrix().allFinite();
    };
    std::vector<AcceptedLoop> loops;
    for (std::size_t q = 0; q < queries.size(); ++q) {
        const LoopQuery& query = queries[q];
        for (std::size_t c = 0; c < query.verifications.size(); ++c) {
            const std::size_t match = query.candidates[c].index;
            if (!query.verifications[c].accepted || !known(query.query) || !known(match)) continue;
            loops.push_back({q, c, query.query, match, path_m_of(query.query), path_m_of(match)});
        }
    }
    std::sort(loops.begin(), loops.end(), [](const AcceptedLoop& a, const AcceptedLoop& b) {
        return std::tie(a.query_path_m, a.query, a.match) <
               std::tie(b.query_path_m, b.query, b.match);
    });
    return loops;
}

}  // namespace

std::size_t RejectLoopsUnlikeTheirRevisit(
    std::vector<LoopQuery>& queries,
    const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of, const OdometryGate& gate,
    double window_m) {
    const std::vector<AcceptedLoop> loops =
        AcceptedLoopsTheOdometryKnows(queries, T_odom_sensor_of, path_m_of);
    const auto T_of = [&](const AcceptedLoop& loop) {
        return queries[loop.query_index].verifications[loop.candidate].T_match_query;
    };
    // Where loop `from` and the odometry's links from its scans put the query of loop `to`.
    const auto Carried = [&](const AcceptedLoop& from, const AcceptedLoop& to) {
        return T_odom_sensor_of(to.match).inverse() * T_odom_sensor_of(from.match) * T_of(from) *
               T_odom_sensor_of(from.query).inverse() * T_odom_sensor_of(to.query);
    };
    // Loops that agree with a neighbour form a chain; a pair that disagrees sets two chains
    // against each other.
    std::vector<std::size_t> chain(loops.size());
    std::iota(chain.begin(), chain.end(), std::size_t{0});
    const auto root = [&chain](std::size_t i) {
        while (chain[i] != i) i = chain[i] = chain[chain[i]];
        return i;
    };
    std::vector<std::pair<std::size_t, std::size_t>> disagreeing;
    for (std::size_t i = 0; i < loops.size(); ++i) {
        const AcceptedLoop& loop = loops[i];
        // Sorted by the query's path: the loops within the window after i follow it.
        for (std::size_t j = i + 1;
             j < loops.size() && loops[j].query_path_m <= loop.query_path_m + window_m; ++j) {
            const AcceptedLoop& other = loops[j];
            if (std::abs(other.match_path_m - loop.match_path_m) > window_m) continue;
            const double links_m = std::abs(other.query_path_m - loop.query_path_m) +
                                   std::abs(other.match_path_m - loop.match_path_m);
            // The gate measures in the frame of the loop it judges: each way round.
            if (gate(T_of(loop), Carried(other, loop), links_m) ||
                gate(T_of(other), Carried(loop, other), links_m)) {
                disagreeing.emplace_back(i, j);
            } else {
                chain[root(i)] = root(j);
            }
        }
    }
    // A chain's length: its queries (a query's further loops for the pose graph count once).
    std::vector<std::pair<std::size_t, std::size_t>> chain_queries;
    for (std::size_t i = 0; i < loops.size(); ++i)
        chain_queries.emplace_back(root(i), loops[i].query_index);
    std::sort(chain_queries.begin(), chain_queries.end());
    chain_queries.erase(std::unique(chain_queries.begin(), chain_queries.end()),
                        chain_queries.end());
    std::vector<std::size_t> chain_size(loops.size(), 0);
    for (const auto& [chain_root, query_index] : chain_queries) ++chain_size[chain_root];
    // Of two chains that disagree, the shorter is rejected; of two as long, both.
    std::vector<bool> rejected_chain(loops.size(), false);
    for (const auto& [i, j] : disagreeing) {
        const std::size_t a = root(i);
        const std::size_t b = root(j);
        if (a == b) continue;  // a chain that bridges two poses: the pair alone cannot tell
        if (chain_size[a] <= chain_size[b]) rejected_chain[a] = true;
        if (chain_size[b] <= chain_size[a]) rejected_chain[b] = true;
    }
    std::size_t rejected = 0;
    for (std::size_t i = 0; i < loops.size(); ++i) {
        if (!rejected_chain[root(i)]) continue;
        registration::Verification& verdict =
            queries[loops[i].query_index].verifications[loops[i].candidate];
        verdict.accepted = false;
        verdict.reason = registration::RejectReason::kUnlikeRevisit;
        ++rejected;
    }
    for (LoopQuery& query : queries) {
        if (query.verified()) query.accepted = query.loop().has_value();
    }
    return rejected;
}

LoopCheck CheckAgainstOdometry(std::function<core::Transform(std::size_t)> T_odom_sensor_of,
                               std::function<double(std::size_t)> path_m_of, OdometryGate gate,
                               std::atomic<std::size_t>* rejected,
                               std::function<Eigen::Vector3d(std::size_t)> view_centre_of) {
    LoopCheck check;
    if (view_centre_of) {
        check.view_distance_m = [T_odom_sensor_of, view_centre_of](std::size_t query,
                                                                   std::size_t match) {
            return (T_odom_sensor_of(query) * view_centre_of(query) -
                    T_odom_sensor_of(match) * view_centre_of(match))
                .norm();
        };
    }
    check.reject = [T_odom_sensor_of, path_m_of, gate, rejected](LoopQuery& query) {
        const std::size_t count =
            RejectLoopsAgainstOdometry(query, T_odom_sensor_of, path_m_of, gate);
        if (rejected != nullptr) *rejected += count;
    };
    check.judge_revisits = [T_odom_sensor_of, path_m_of, gate](std::vector<LoopQuery>& queries,
                                                               double window_m) {
        return RejectLoopsUnlikeTheirRevisit(queries, T_odom_sensor_of, path_m_of, gate, window_m);
    };
    check.allowed_poses = [T_odom_sensor_of, path_m_of, gate](std::size_t query,
                                                              std::size_t match) {
        return OdometryAllowedPoses(query, match, T_odom_sensor_of, path_m_of, gate);
    };
    if (gate.rotation_allowance_deg) {
        check.yaw_window = [T_odom_sensor_of, path_m_of, gate](std::size_t query,
                                                               std::size_t match) {
            return OdometryYawWindow(query, match, T_odom_sensor_of, path_m_of, gate);
        };
    }
    check.may_close = [T_odom_sensor_of, path_m_of, gate](std::size_t query, std::size_t match,
                                                          double max_loop_distance_m) {
        return OdometryAllowsALoop(query, match, max_loop_distance_m, T_odom_sensor_of, path_m_of,
                                   gate);
    };
    if (gate.translation_allowance_m) {
        check.in_reach_bound =
            [T_odom_sensor_of, path_m_of, allowance_m = gate.translation_allowance_m](
                std::size_t query, std::size_t match, double max_loop_distance_m) {
                return MayBeInReach(query, match, max_loop_distance_m, T_odom_sensor_of, path_m_of,
                                    allowance_m);
            };
    }
    return check;
}

std::vector<Neighbor> NearestCandidates(std::size_t count, std::size_t k,
                                        const std::function<double(std::size_t)>& distance_of,
                                        const std::function<bool(std::size_t)>& eligible) {
    const auto before = [](const Neighbor& a, const Neighbor& b) {
        return a.distance < b.distance || (a.distance == b.distance && a.index < b.index);
    };
    // A bounded max-heap of the k best so far (the worst on top): O(k) memory, not O(count).
    std::vector<Neighbor> best;
    best.reserve(std::min(k, count));
    for (std::size_t j = 0; j < count && k > 0; ++j) {
        if (eligible && !eligible(j)) continue;
        const Neighbor candidate{j, distance_of(j)};
        // A missing scan (+inf) is never a candidate (NaN neither).
        if (!(candidate.distance < std::numeric_limits<double>::infinity())) continue;
        if (best.size() < k) {
            best.push_back(candidate);
            std::push_heap(best.begin(), best.end(), before);
        } else if (before(candidate, best.front())) {
            std::pop_heap(best.begin(), best.end(), before);
            best.back() = candidate;
            std::push_heap(best.begin(), best.end(), before);
        }
    }
    std::sort_heap(best.begin(), best.end(), before);
    return best;
}

LoopCheck LayoutOrderOf(const std::vector<registration::CompactPreparedScan>& scans,
                        const registration::CoarseConfig& coarse,
                        const registration::CompactPreparedScan* query) {
    const auto layout_of = [&scans, query](std::size_t i) -> const registration::LayoutSignature& {
        static const registration::LayoutSignature kNone;
        if (i < scans.size()) return scans[i].layout();
        return query != nullptr && i == scans.size() ? query->layout() : kNone;
    };
    LoopCheck check;
    check.layout_similarity = [layout_of](std::size_t a, std::size_t b) {
        return registration::LayoutSimilarity(layout_of(a), layout_of(b));
    };
    if (coarse.layout_yaw_window_deg < 180.0) {
        check.yaw_window = [layout_of, coarse](std::size_t query_scan, std::size_t match) {
            return registration::LayoutYawWindow(layout_of(query_scan), layout_of(match), coarse);
        };
    }
    return check;
}

LoopDetector::LoopDetector(const core::DescriptorConfig& descriptor, const DetectorConfig& detector)
    : LoopDetector(DescriptorDatabase(descriptor), detector) {}

LoopDetector::LoopDetector(DescriptorDatabase database, const DetectorConfig& detector,
                           std::vector<registration::PreparedScan> scans)
    : database_(std::move(database)),
      detector_(detector),
      threshold_(detector.ThresholdFor(database_.method())),
      scans_(scans.begin(), scans.end()),
      neighbours_(std::make_unique<NeighbourOverlaps>(
          [this](std::size_t j) { return expanded_.Get(scans_, j); },
          [this] { return scans_.size(); }, detector.verification)) {
    detector_.Validate();
    if (!scans_.empty() && scans_.size() != database_.size()) {
        throw core::ConfigError("LoopDetector: " + std::to_string(scans_.size()) +
                                " prepared scans for a database of " +
                                std::to_string(database_.size()));
    }
    scans_.resize(database_.size());
    session_start_ = database_.size();
    database_.definition().ValidateThreshold(threshold_);
    index_ = database_.store().MakeIndex();
    // One sort instead of n sorted inserts: a loaded map may hold a million scans.
    if (index_) index_->InsertAll([this](std::size_t i) { return database_.IsValid(i); });
}

LoopDetector::~LoopDetector() = default;

LoopQuery LoopDetector::Search(const PreparedQuery& query, std::size_t query_index,
                               const std::function<bool(std::size_t)>& eligible,
                               const std::vector<double>& path_m, const LoopCheck& check) const {
    const CandidateSearch search = [&](std::size_t count, const Filter& filter) {
        if (index_) return index_->Search(query, count, filter);
        return NearestCandidates(
            database_.size(), count, [&](std::size_t j) { return database_.Distance(query, j); },
            filter);
    };
    // Without the path (no odometry, or localisation) a gap in metres leaves second_ratio NaN.
    return RankCandidates(query_index, search, eligible,
                          detector_.min_gap.Along(database_.times_s(), path_m), detector_,
                          database_.definition(), threshold_, check);
}

void LoopDetector::Verify(LoopQuery& result, const registration::CompactPreparedScan& scan,
                          const LoopCheck& check) const {
    if (!detector_.verify || !scan.prepared()) return;
    // The query as it is stored: online, offline and localisation see the same scans.
    const registration::PreparedScan query = scan.Expand();
    // The query is not stored yet (Process, or a localisation query searched as the scan after
    // the stored ones): its neighbour is the last stored scan, registered here, once, if asked.
    std::optional<double> query_reference;
    const auto reference_of = [&](std::size_t j) {
        if (j < scans_.size()) return neighbours_->Of(j);
        if (!query_reference) {
            query_reference = scans_.empty() ? kNan
                                             : NeighbourOverlaps::Between(
                                                   query, expanded_.Get(scans_, scans_.size() - 1),
                                                   detector_.verification)
                                                   .distinctive_overlap;
        }
        return *query_reference;
    };
    // No motion rule online: its chain from a match up to the query would register, at the
    // first loop of a revisit, every scan from the match to the next turn at once (offline it
    // costs at most a registration per scan; docs/verification.md, "The scans' own motion").
    const LoopCheck judge = JudgeOf(check, reference_of, {}, detector_.verification);
    VerifyQuery(
        result, query, [this](std::size_t j) { return expanded_.Get(scans_, j); }, detector_,
        database_.method(), nullptr, nullptr, Execution::kParallel, judge);
}

std::size_t LoopDetector::prepared_bytes() const {
    std::size_t bytes = 0;
    for (const registration::CompactPreparedScan& scan : scans_) bytes += scan.MemoryBytes();
    return bytes;
}

LoopQuery LoopDetector::Process(const core::PointCloud& scan, double time_s,
                                const std::optional<core::Transform>& T_odom_sensor) {
    registration::PreparedScan prepared;
    if (detector_.verify)
        prepared = registration::PrepareScan(scan, detector_.verification.reduction);
    return Process(ComputeDescriptor(scan, database_.config()), time_s, std::move(prepared),
                   T_odom_sensor);
}

std::optional<double> LoopDetector::PathOf(
    const std::optional<core::Transform>& T_odom_sensor) const {
    const std::size_t index = database_.size();
    const std::size_t in_session = index - session_start_;  // scans processed before this one
    if (!T_odom_sensor) {
        if (!odometry_.empty()) {
            throw core::ConfigError("scan " + std::to_string(index) +
                                    " has no odometry pose, the scans before it had one: give "
                                    "the pose with every scan or with none");
        }
        if (detector_.min_gap.unit == core::MinGap::Unit::kMetres) {
            throw core::ConfigError(
                "detection.min_gap_unit metres needs the path: give each scan's odometry pose "
                "(T_odom_sensor) to Process, or the gap in scans or seconds");
        }
        return std::nullopt;
    }
    if (odometry_.size() != in_session) {
        throw core::ConfigError("scan " + std::to_string(index) +
                                " has an odometry pose, the scans before it had none: give the "
                                "pose with every scan or with none");
    }
    if (!T_odom_sensor->matrix().allFinite()) {
        throw core::ConfigError("the odometry pose of scan " + std::to_string(index) +
                                " is not finite");
    }
    if (in_session == 0) return 0.0;
    return path_m_.back() + (T_odom_sensor->translation() - odometry_.back().translation()).norm();
}

LoopQuery LoopDetector::Process(const core::Descriptor& descriptor, double time_s,
                                registration::PreparedScan scan,
                                const std::optional<core::Transform>& T_odom_sensor) {
    // The gap in seconds counts back in time: within a session, time may not go back (a loaded
    // map's scans may be of any time).
    database_.CheckTime(time_s);  // before the search, which measures gaps in time
    const std::size_t index = database_.size();
    if (index > session_start_ && time_s < database_.times_s().back()) {
        throw core::ConfigError("scan " + std::to_string(index) + ": time " +
                                core::NumberText(time_s) + " s goes back from the scan before (" +
                                core::NumberText(database_.times_s().back()) + " s)");
    }
    const std::optional<double> query_path_m = PathOf(T_odom_sensor);
    const std::unique_ptr<PreparedQuery> query = database_.Prepare(descriptor);
    const std::size_t query_index = database_.size();
    const core::MinGap gap = detector_.min_gap;
    const bool in_metres = gap.unit == core::MinGap::Unit::kMetres;
    const std::vector<double>& times_s = database_.times_s();
    // Scan j's odometry pose and path; a loaded map's scans have none (NaN).
    const auto pose_of = [&](std::size_t j) {
        if (j == query_index) return *T_odom_sensor;
        if (j < session_start_) return core::Transform(kUnknownPose);
        return odometry_[j - session_start_];
    };
    const auto path_of = [&](std::size_t j) {
        if (j == query_index) return *query_path_m;
        return j < session_start_ ? kNan : path_m_[j - session_start_];
    };
    // Where the scans look, for the order of the candidates (NaN for a scan given unprepared).
    const auto view_of = [&](std::size_t j) {
        return j == query_index ? scan.view_centre : scans_[j].view_centre();
    };
    LoopCheck odometry_check;
    if (odometry_gate_ && query_path_m)
        odometry_check = CheckAgainstOdometry(pose_of, path_of, odometry_gate_, nullptr, view_of);
    registration::CompactPreparedScan compact(scan);
    LoopCheck search_check;
    if (detector_.verify)
        search_check = odometry_check
                           ? odometry_check
                           : LayoutOrderOf(scans_, detector_.verification.coarse, &compact);
    LoopQuery result = Search(
        *query, query_index,
        [&](std::size_t j) {
            if (j >= query_index || !database_.IsValid(j)) return false;
            // A map's scan (path NaN) belongs to another session: no path separates it from this.
            if (query_path_m && !detector_.PathAllows(*query_path_m, path_of(j))) return false;
            if (in_metres)
                return j < session_start_ || gap.Allows(query_index, j, *query_path_m, path_of(j));
            return gap.Allows(query_index, j, time_s, times_s[j]);
        },
        session_start_ == 0 ? path_m_ : std::vector<double>{}, search_check);
    // Without odometry the layouts bound the yaws the pairs search.
    Verify(result, compact, search_check);
    database_.Add(descriptor, time_s);
    scans_.push_back(std::move(compact));
    if (query_path_m) odometry_.push_back(*T_odom_sensor), path_m_.push_back(*query_path_m);
    if (index_) index_->Insert(query_index);
    return result;
}

LoopQuery LoopDetector::Query(const core::Descriptor& descriptor,
                              const registration::PreparedScan& scan) const {
    return Query(*database_.Prepare(descriptor), database_.size(), scan);
}

LoopQuery LoopDetector::Query(const PreparedQuery& query, std::size_t query_index,
                              const registration::PreparedScan& scan) const {
    return Query(query, query_index, registration::CompactPreparedScan(scan));
}

LoopQuery LoopDetector::Query(const PreparedQuery& query, std::size_t query_index,
                              const registration::CompactPreparedScan& scan) const {
    // Searched and judged as the scan after the stored ones (its neighbour is the last stored
    // scan); `query_index`, an index of another sequence, only labels the result.
    const LoopCheck layouts = detector_.verify
                                  ? LayoutOrderOf(scans_, detector_.verification.coarse, &scan)
                                  : LoopCheck{};
    LoopQuery result = Search(
        query, database_.size(), [&](std::size_t j) { return database_.IsValid(j); }, {}, layouts);
    Verify(result, scan, layouts);
    result.query = query_index;
    return result;
}

std::vector<LoopQuery> LocaliseSequence(
    const LoopDetector& map, const DescriptorDatabase& queries, Execution execution,
    const std::vector<registration::CompactPreparedScan>& query_scans) {
    if (queries.config() != map.database().config()) {
        throw core::ConfigError(
            "the query scans were described with another configuration than the map's");
    }
    std::vector<LoopQuery> results(queries.size());
    const auto localise = [&](std::size_t i) {
        results[i].query = i;
        if (!queries.IsValid(i)) return;
        results[i] = map.Query(
            *queries.PrepareStored(i), i,
            i < query_scans.size() ? query_scans[i] : registration::CompactPreparedScan{});
    };
    if (execution == Execution::kSerial) {
        for (std::size_t i = 0; i < queries.size(); ++i) localise(i);
    } else {
        tbb::parallel_for(std::size_t{0}, queries.size(), localise);
    }
    return results;
}

std::vector<LoopQuery> DetectFromMatrix(const SimilarityMatrix& matrix,
                                        const std::vector<double>& times_s,
                                        const DetectorConfig& detector, const core::Method& method,
                                        const std::vector<double>& path_m, const LoopCheck& check) {
    const double threshold =
        CheckOfflineDetection(detector, method, times_s, path_m, matrix.size());
    const std::vector<double>& along = detector.min_gap.Along(times_s, path_m);
    std::vector<LoopQuery> results(matrix.size());
    for (std::size_t i = 0; i < matrix.size(); ++i) {
        const auto distance_of = [&](std::size_t j) { return double{matrix.at(i, j)}; };
        results[i] = DetectOne(
            i,
            [&](std::size_t count, const Filter& filter) {
                return NearestCandidates(i, count, distance_of, filter);
            },
            along, path_m, detector, MethodOf(method), threshold, check);
    }
    return results;
}

StreamingDetection::StreamingDetection(const DescriptorDatabase& database,
                                       const DetectorConfig& detector,
                                       const std::vector<double>& path_m, const LoopCheck& check)
    : database_(database),
      detector_(detector),
      path_m_(path_m),
      check_(check),
      threshold_(CheckOfflineDetection(detector, database.method(), database.times_s(), path_m,
                                       database.size())),
      along_(detector.min_gap.Along(database.times_s(), path_m)),
      index_(database.store().MakeIndex()) {
    // Over the valid scans; candidates are filtered to j < i, so one index serves every query.
    if (index_) index_->InsertAll([&](std::size_t j) { return database.IsValid(j); });
}

StreamingDetection::~StreamingDetection() = default;

LoopQuery StreamingDetection::Detect(std::size_t i) const {
    const std::unique_ptr<PreparedQuery> query =
        index_ && database_.IsValid(i) ? database_.PrepareStored(i) : nullptr;
    std::vector<float> row;  // the query's distances to the earlier scans, as the matrix holds
    bool row_filled = false;
    const auto fill_row = [&] {
        row.resize(i);
        for (std::size_t j = 0; j < i; ++j) {
            // Distance(j, i) with j < i, rounded to float: the matrix's entry (j, i).
            if (detector_.min_gap.Allows(i, j, along_[i], along_[j]))
                row[j] = static_cast<float>(database_.Distance(j, i));
        }
        row_filled = true;
    };
    const CandidateSearch search = [&](std::size_t count, const Filter& filter) {
        if (query) {
            const std::size_t asked = count + kIndexMargin;
            if (auto ranked =
                    RankedAsTheMatrix(index_->Search(*query, asked, filter), count, asked))
                return *ranked;
        }
        if (!row_filled) fill_row();
        return NearestCandidates(
            i, count, [&](std::size_t j) { return double{row[j]}; }, filter);
    };
    return DetectOne(i, search, along_, path_m_, detector_, database_.definition(), threshold_,
                     check_);
}

std::vector<LoopQuery> DetectStreaming(const DescriptorDatabase& database,
                                       const DetectorConfig& detector, Execution execution,
                                       const std::vector<double>& path_m, const LoopCheck& check) {
    const StreamingDetection detection(database, detector, path_m, check);
    std::vector<LoopQuery> results(database.size());
    const auto detect_rows = [&](const tbb::blocked_range<std::size_t>& rows) {
        for (std::size_t i = rows.begin(); i < rows.end(); ++i) results[i] = detection.Detect(i);
    };
    const tbb::blocked_range<std::size_t> all(0, database.size());
    if (execution == Execution::kSerial) {
        detect_rows(all);
    } else {
        tbb::parallel_for(all, detect_rows);
    }
    return results;
}

}  // namespace lidarloop::pipeline

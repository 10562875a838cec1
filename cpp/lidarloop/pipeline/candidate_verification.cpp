#include "lidarloop/pipeline/candidate_verification.hpp"

#include <algorithm>
#include <optional>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "lidarloop/core/stopwatch.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"
#include "lidarloop/pipeline/expanded_scans.hpp"
#include "lidarloop/pipeline/neighbour_overlaps.hpp"

namespace lidarloop::pipeline {
namespace {

void AppendTo(std::vector<double>& to, const std::vector<double>& from) {
    to.insert(to.end(), from.begin(), from.end());
}

registration::Verification Rejected(registration::RejectReason reason) {
    registration::Verification rejected;
    rejected.reason = reason;
    return rejected;
}

// Whether candidate `c` is to be registered in rank order: until the query has a loop, every
// one; after that, those `more` wants.
bool Wanted(const LoopQuery& query, std::size_t c, const MoreLoopsWanted& more) {
    const bool has_loop = std::any_of(query.verifications.begin(),
                                      query.verifications.begin() + static_cast<std::ptrdiff_t>(c),
                                      [](const auto& v) { return v.accepted; });
    return !has_loop || (more && more(query, c));
}

// detector.stop_at_first_loop: the candidates in rank order, `width` at a time. A batch's wanted
// candidates are registered at once (`register_batch`), then decided in rank order as if
// registered one after another: a candidate no longer wanted by then gets kNotNeeded whatever
// was found, so the verdicts do not depend on `width`. `answered[c]`: c has its verdict already.
void DecideInRankOrder(LoopQuery& query, std::vector<bool> answered, std::size_t width,
                       const std::function<void(const std::vector<std::size_t>&)>& register_batch,
                       const LoopCheck& check, const MoreLoopsWanted& more) {
    const std::size_t n = query.candidates.size();
    const auto pruned = [&](std::size_t c) {
        return query.verifications[c].reason == registration::RejectReason::kPruned;
    };
    for (std::size_t begin = 0; begin < n; begin += width) {
        const std::size_t end = std::min(n, begin + width);
        std::vector<std::size_t> batch;  // wanted as far as the decided candidates tell
        for (std::size_t c = begin; c < end; ++c) {
            if (!answered[c] && !pruned(c) && Wanted(query, c, more)) batch.push_back(c);
        }
        if (!batch.empty()) register_batch(batch);
        for (const std::size_t c : batch) answered[c] = true;
        // Decide in rank order from the state registering one after another would have reached.
        std::vector<registration::Verification> found(
            query.verifications.begin() + static_cast<std::ptrdiff_t>(begin),
            query.verifications.begin() + static_cast<std::ptrdiff_t>(end));
        for (std::size_t c = begin; c < end; ++c) {
            if (!pruned(c)) query.verifications[c] = registration::Verification{};
        }
        for (std::size_t c = begin; c < end; ++c) {
            if (pruned(c)) continue;  // never reset
            if (!Wanted(query, c, more)) {
                query.verifications[c] = Rejected(registration::RejectReason::kNotNeeded);
                continue;
            }
            if (answered[c]) {
                query.verifications[c] = found[c - begin];
            } else {  // a loop before it in the batch was rejected by the check
                register_batch({c});
                answered[c] = true;
            }
            if (query.verifications[c].accepted && check) check(query);
        }
    }
}

}  // namespace

std::uint64_t VerificationCache::Key(std::size_t query, std::size_t match) {
    return (static_cast<std::uint64_t>(query) << 32U) ^ static_cast<std::uint64_t>(match);
}

std::optional<registration::Verification> VerificationCache::Find(std::size_t query,
                                                                  std::size_t match) const {
    const std::lock_guard lock(mutex_);
    const auto found = verdicts_.find(Key(query, match));
    if (found == verdicts_.end()) return std::nullopt;
    return found->second;
}

void VerificationCache::Store(std::size_t query, std::size_t match,
                              const registration::Verification& verdict) {
    const std::lock_guard lock(mutex_);
    verdicts_.insert_or_assign(Key(query, match), verdict);
}

std::size_t VerificationCache::size() const {
    const std::lock_guard lock(mutex_);
    return verdicts_.size();
}

void VerificationTimes::Append(const VerificationTimes& other) {
    AppendTo(pair_seconds, other.pair_seconds);
    AppendTo(query_seconds, other.query_seconds);
    AppendTo(pair_cpu_seconds, other.pair_cpu_seconds);
    AppendTo(query_cpu_seconds, other.query_cpu_seconds);
}

void VerifyQuery(LoopQuery& query, const registration::PreparedScan& prepared,
                 const std::function<registration::PreparedScan(std::size_t)>& match_of,
                 const DetectorConfig& detector, const core::Method& method,
                 VerificationTimes* times, VerificationCache* cache, Execution execution,
                 const LoopCheck& check, const MoreLoopsWanted& more) {
    query.verifications.clear();
    query.accepted = false;
    if (!query.has_match()) return;
    if (!prepared.structure) {  // a skipped scan
        query.verifications.assign(query.candidates.size(),
                                   Rejected(registration::RejectReason::kTooFewPoints));
        return;
    }
    // Pruned and cached candidates, and those the odometry rules out whatever their registration,
    // are answered at once; the others are registered.
    const DescriptorMethod& definition = MethodOf(method);
    query.verifications.resize(query.candidates.size());
    std::vector<bool> answered(query.candidates.size(), false);
    for (std::size_t c = 0; c < query.candidates.size(); ++c) {
        const Neighbor& candidate = query.candidates[c];
        std::optional<registration::Verification> cached;
        if (cache) cached = cache->Find(query.query, candidate.index);
        if (detector.threshold && !definition.IsMatch(candidate.distance, *detector.threshold)) {
            query.verifications[c] = Rejected(registration::RejectReason::kPruned);
            answered[c] = true;
        } else if (!check.MayClose(query.query, candidate.index,
                                   detector.verification.acceptance.max_loop_distance_m)) {
            query.verifications[c] = Rejected(registration::RejectReason::kOdometryMismatch);
            answered[c] = true;
        } else if (cached) {
            query.verifications[c] = *cached;
            answered[c] = true;
        }
    }
    std::vector<registration::YawWindow> yaws;  // each candidate's, where the check gives them
    for (const Neighbor& candidate : query.candidates)
        yaws.push_back(check.YawWindow(query.query, candidate.index));
    // Where the scans' own motion judges a pair, its looser degeneracy floor.
    registration::VerificationConfig judged_by_motion = detector.verification;
    judged_by_motion.acceptance.min_constraining_points =
        detector.verification.acceptance.min_constraining_points_with_motion;
    std::optional<registration::CoarseQuery> coarse;  // the query's images, shared by its pairs
    std::vector<double> pair_seconds(query.candidates.size(), -1.0);
    std::vector<double> pair_cpu_seconds(query.candidates.size(), -1.0);
    const auto register_one = [&](std::size_t c) {
        const std::size_t match = query.candidates[c].index;
        const core::Stopwatch pair_wall;
        const core::ThreadCpuStopwatch pair_cpu;
        const registration::VerificationConfig& config =
            check.MotionJudges(query.query, match) ? judged_by_motion : detector.verification;
        query.verifications[c] =
            registration::Verify(prepared, *coarse, match_of(match), config,
                                 check.AllowedPoses(query.query, match), yaws[c]);
        pair_cpu_seconds[c] = pair_cpu.Seconds();
        pair_seconds[c] = pair_wall.Seconds();
        if (cache) cache->Store(query.query, match, query.verifications[c]);
    };
    const auto make_coarse = [&] {
        const core::Stopwatch query_wall;
        const core::ThreadCpuStopwatch query_cpu;
        // The images of the yaws some candidate still to be registered may take.
        std::vector<registration::YawWindow> windows;
        for (std::size_t c = 0; c < query.candidates.size(); ++c) {
            if (!answered[c]) windows.push_back(yaws[c]);
        }
        coarse.emplace(*prepared.structure, detector.verification.coarse, windows);
        if (times) {
            times->query_cpu_seconds.push_back(query_cpu.Seconds());
            times->query_seconds.push_back(query_wall.Seconds());
        }
    };
    if (detector.stop_at_first_loop) {
        // In rank order: the first accepted candidate that the check keeps is the loop; after
        // it, only the candidates `more` still wants. Online, as many at once as there are
        // threads: a query's latency, not its CPU time, is what keeps up with the sensor.
        const auto width =
            execution == Execution::kParallel
                ? static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()))
                : std::size_t{1};
        const auto register_batch = [&](const std::vector<std::size_t>& batch) {
            if (!coarse) make_coarse();
            if (batch.size() == 1) return register_one(batch.front());
            tbb::parallel_for(std::size_t{0}, batch.size(),
                              [&](std::size_t k) { register_one(batch[k]); });
        };
        DecideInRankOrder(query, answered, width, register_batch, check, more);
    } else {
        std::vector<std::size_t> to_register;
        for (std::size_t c = 0; c < query.candidates.size(); ++c) {
            if (!answered[c]) to_register.push_back(c);
        }
        if (!to_register.empty()) make_coarse();
        if (execution == Execution::kParallel) {
            tbb::parallel_for(std::size_t{0}, to_register.size(),
                              [&](std::size_t k) { register_one(to_register[k]); });
        } else {
            for (const std::size_t c : to_register) register_one(c);
        }
        if (check) check(query);
    }
    if (times) {
        for (std::size_t c = 0; c < pair_seconds.size(); ++c) {
            if (pair_seconds[c] < 0.0) continue;  // not registered
            times->pair_seconds.push_back(pair_seconds[c]);
            times->pair_cpu_seconds.push_back(pair_cpu_seconds[c]);
        }
    }
    query.accepted = query.loop().has_value();
}

VerificationTimes VerifyQueries(std::vector<LoopQuery>& queries,
                                const std::vector<registration::CompactPreparedScan>& scans,
                                const DetectorConfig& detector, const core::Method& method,
                                Execution execution, const ProgressReport& progress,
                                VerificationCache* cache, const LoopCheck& check,
                                const MoreLoopsWanted& more, NeighbourOverlaps* neighbours) {
    ExpandedScans expanded;
    const auto scan_of = [&](std::size_t i) { return expanded.Get(scans, i); };
    std::optional<NeighbourOverlaps> own_neighbours;
    if (neighbours == nullptr) {
        neighbours = &own_neighbours.emplace(
            scan_of, [&scans] { return scans.size(); }, detector.verification);
    }
    const LoopCheck judge = JudgeOf(
        check, [neighbours](std::size_t scan) { return neighbours->Of(scan); },
        [neighbours](std::size_t scan) { return neighbours->StepOf(scan); }, detector.verification,
        [neighbours](std::size_t scan) { return neighbours->ChainStart(scan); });
    std::vector<VerificationTimes> per_query(queries.size());
    ProgressCounter done(progress, queries.size());
    const auto run = [&](std::size_t i) {
        // Queries run in parallel: stopping at the first loop, each registers its candidates one
        // after another (a batch at once would register some for nothing).
        const Execution per_query_execution =
            detector.stop_at_first_loop ? Execution::kSerial : execution;
        VerifyQuery(queries[i], scan_of(queries[i].query), scan_of, detector, method, &per_query[i],
                    cache, per_query_execution, judge, more);
        done.Add();
    };
    if (execution == Execution::kParallel) {
        tbb::parallel_for(std::size_t{0}, queries.size(), run);
    } else {
        for (std::size_t i = 0; i < queries.size(); ++i) run(i);
    }
    const double revisit_path_m = detector.verification.acceptance.revisit_path_m;
    if (check.judge_revisits && revisit_path_m > 0.0) check.judge_revisits(queries, revisit_path_m);
    VerificationTimes times;
    for (const auto& t : per_query) times.Append(t);
    return times;
}

}  // namespace lidarloop::pipeline

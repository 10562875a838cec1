#include "lidarloop/pipeline/candidate_verification.hpp"

#include <atomic>
#include <chrono>

#include <tbb/parallel_for.h>

#include "lidarloop/pipeline/descriptor_method.hpp"
#include "lidarloop/pipeline/expanded_scans.hpp"

namespace lidarloop::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

registration::Verification Rejected(registration::RejectReason reason) {
    registration::Verification rejected;
    rejected.reason = reason;
    return rejected;
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

void VerifyQuery(LoopQuery& query, const registration::PreparedScan& prepared,
                 const std::function<registration::PreparedScan(std::size_t)>& match_of,
                 const DetectorConfig& detector, const core::Method& method,
                 VerificationTimes* times, VerificationCache* cache, Execution execution) {
    query.verifications.clear();
    query.accepted = false;
    if (!query.has_match()) return;
    if (!prepared.structure) {  // a skipped scan
        query.verifications.assign(query.candidates.size(),
                                   Rejected(registration::RejectReason::kTooFewPoints));
        return;
    }
    // Pruned and cached candidates are answered at once; the others are registered.
    const DescriptorMethod& definition = MethodOf(method);
    query.verifications.resize(query.candidates.size());
    std::vector<std::size_t> to_register;
    for (std::size_t c = 0; c < query.candidates.size(); ++c) {
        const Neighbor& candidate = query.candidates[c];
        std::optional<registration::Verification> cached;
        if (cache) cached = cache->Find(query.query, candidate.index);
        if (detector.threshold && !definition.IsMatch(candidate.distance, *detector.threshold)) {
            query.verifications[c] = Rejected(registration::RejectReason::kPruned);
        } else if (cached) {
            query.verifications[c] = *cached;
        } else {
            to_register.push_back(c);
        }
    }
    if (!to_register.empty()) {
        const auto query_start = Clock::now();
        const registration::CoarseQuery coarse(*prepared.structure, detector.verification.coarse);
        if (times) times->query_seconds.push_back(SecondsSince(query_start));
        std::vector<double> pair_seconds(to_register.size());
        const auto register_one = [&](std::size_t k) {
            const std::size_t c = to_register[k];
            const std::size_t match = query.candidates[c].index;
            const auto pair_start = Clock::now();
            query.verifications[c] =
                registration::Verify(prepared, coarse, match_of(match), detector.verification);
            pair_seconds[k] = SecondsSince(pair_start);
            if (cache) cache->Store(query.query, match, query.verifications[c]);
        };
        if (execution == Execution::kParallel) {
            tbb::parallel_for(std::size_t{0}, to_register.size(), register_one);
        } else {
            for (std::size_t k = 0; k < to_register.size(); ++k) register_one(k);
        }
        if (times) {
            times->pair_seconds.insert(times->pair_seconds.end(), pair_seconds.begin(),
                                       pair_seconds.end());
        }
    }
    query.accepted = query.loop().has_value();
}

VerificationTimes VerifyQueries(std::vector<LoopQuery>& queries,
                                const std::vector<registration::CompactPreparedScan>& scans,
                                const DetectorConfig& detector, const core::Method& method,
                                Execution execution,
                                const std::function<void(std::size_t, std::size_t)>& progress,
                                VerificationCache* cache) {
    ExpandedScans expanded;
    const auto scan_of = [&](std::size_t i) { return expanded.Get(scans, i); };
    std::vector<VerificationTimes> per_query(queries.size());
    std::atomic<std::size_t> done{0};
    const auto run = [&](std::size_t i) {
        VerifyQuery(queries[i], scan_of(queries[i].query), scan_of, detector, method, &per_query[i],
                    cache, execution);
        const std::size_t finished = ++done;
        if (progress) progress(finished, queries.size());
    };
    if (execution == Execution::kParallel) {
        tbb::parallel_for(std::size_t{0}, queries.size(), run);
    } else {
        for (std::size_t i = 0; i < queries.size(); ++i) run(i);
    }
    VerificationTimes times;
    for (const auto& t : per_query) {
        times.pair_seconds.insert(times.pair_seconds.end(), t.pair_seconds.begin(),
                                  t.pair_seconds.end());
        times.query_seconds.insert(times.query_seconds.end(), t.query_seconds.begin(),
                                   t.query_seconds.end());
    }
    return times;
}

}  // namespace lidarloop::pipeline

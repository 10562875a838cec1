#include "lidarloop/pipeline/candidate_verification.hpp"

#include <atomic>
#include <chrono>

#include <tbb/parallel_for.h>

#include "lidarloop/pipeline/descriptor_method.hpp"

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

void VerifyQuery(LoopQuery& query,
                 const std::function<const registration::PreparedScan&(std::size_t)>& scan_of,
                 const DetectorConfig& detector, const core::Method& method,
                 VerificationTimes* times) {
    query.verifications.clear();
    query.accepted = false;
    if (!query.has_match()) return;
    const registration::PreparedScan& prepared = scan_of(query.query);
    if (!prepared.structure) {  // a skipped scan
        query.verifications.assign(query.candidates.size(),
                                   Rejected(registration::RejectReason::kTooFewPoints));
        return;
    }
    const auto query_start = Clock::now();
    const registration::CoarseQuery coarse(*prepared.structure, detector.verification.coarse);
    if (times) times->query_seconds.push_back(SecondsSince(query_start));
    const DescriptorMethod& definition = MethodOf(method);
    for (const Neighbor& candidate : query.candidates) {
        if (detector.threshold && !definition.IsMatch(candidate.distance, *detector.threshold)) {
            query.verifications.push_back(Rejected(registration::RejectReason::kPruned));
            continue;
        }
        const auto pair_start = Clock::now();
        query.verifications.push_back(registration::Verify(
            prepared, coarse, scan_of(candidate.index), detector.verification));
        if (times) times->pair_seconds.push_back(SecondsSince(pair_start));
    }
    query.accepted = query.loop().has_value();
}

VerificationTimes VerifyQueries(std::vector<LoopQuery>& queries,
                                const std::vector<registration::PreparedScan>& scans,
                                const DetectorConfig& detector, const core::Method& method,
                                Execution execution,
                                const std::function<void(std::size_t, std::size_t)>& progress) {
    const auto scan_of = [&scans](std::size_t i) -> const registration::PreparedScan& {
        return scans.at(i);
    };
    std::vector<VerificationTimes> per_query(queries.size());
    std::atomic<std::size_t> done{0};
    const auto run = [&](std::size_t i) {
        VerifyQuery(queries[i], scan_of, detector, method, &per_query[i]);
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

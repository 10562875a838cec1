#include "lidarloop/pipeline/loop_detector.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/parallel_for.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/pipeline/candidate_verification.hpp"

namespace lidarloop::pipeline {
namespace {

double SecondRatio(double best, double second) {
    if (second == 0.0) return 1.0;
    return best / second;
}

// Fills second_ratio and accepted from the candidates and a search for the best candidate
// outside the gap around the best match.
void Finish(LoopQuery& result, const core::MinGap& gap, const std::vector<double>& times_s,
            const DescriptorMethod& method, double threshold,
            const std::function<std::vector<Neighbor>(const std::function<bool(std::size_t)>&)>&
                search_one) {
    if (!result.has_match()) return;
    const Neighbor best = result.candidates.front();
    result.accepted = method.IsMatch(best.distance, threshold);
    const auto other_place = [&](std::size_t j) {
        return gap.Allows(best.index, j, times_s[best.index], times_s[j]);
    };
    const std::vector<Neighbor> second = search_one(other_place);
    if (!second.empty()) result.second_ratio = SecondRatio(best.distance, second.front().distance);
}

}  // namespace

void DetectorConfig::Validate() const {
    min_gap.Validate("detection.min_gap");
    if (threshold && !(std::isfinite(*threshold) && *threshold >= 0.0)) {
        throw core::ConfigError("detection.threshold must be a finite number >= 0, got " +
                                std::to_string(*threshold));
    }
    if (top_k < 1 || top_k > 1000) {
        throw core::ConfigError("detection.top_k must be in [1, 1000], got " +
                                std::to_string(top_k));
    }
    verification.Validate();
}

std::optional<std::size_t> LoopQuery::loop() const {
    if (!verified()) return accepted && has_match() ? std::optional<std::size_t>(0) : std::nullopt;
    for (std::size_t i = 0; i < verifications.size(); ++i) {
        if (verifications[i].accepted) return i;
    }
    return std::nullopt;
}

std::vector<Neighbor> NearestCandidates(std::size_t count, std::size_t k,
                                        const std::function<double(std::size_t)>& distance_of,
                                        const std::function<bool(std::size_t)>& eligible) {
    std::vector<Neighbor> all;
    for (std::size_t j = 0; j < count; ++j) {
        if (!eligible || eligible(j)) all.push_back({j, distance_of(j)});
    }
    const auto before = [](const Neighbor& a, const Neighbor& b) {
        return a.distance < b.distance || (a.distance == b.distance && a.index < b.index);
    };
    const std::size_t keep = std::min(k, all.size());
    std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(keep), all.end(),
                      before);
    all.resize(keep);
    // A missing scan (+inf) is never a candidate.
    while (!all.empty() && !(all.back().distance < std::numeric_limits<double>::infinity())) {
        all.pop_back();
    }
    return all;
}

LoopDetector::LoopDetector(const core::DescriptorConfig& descriptor, const DetectorConfig& detector)
    : LoopDetector(DescriptorDatabase(descriptor), detector) {}

LoopDetector::LoopDetector(DescriptorDatabase database, const DetectorConfig& detector,
                           std::vector<registration::PreparedScan> scans)
    : database_(std::move(database)),
      detector_(detector),
      threshold_(detector.ThresholdFor(database_.method())),
      scans_(std::move(scans)) {
    detector_.Validate();
    if (!scans_.empty() && scans_.size() != database_.size()) {
        throw core::ConfigError("LoopDetector: " + std::to_string(scans_.size()) +
                                " prepared scans for a database of " +
                                std::to_string(database_.size()));
    }
    scans_.resize(database_.size());
    database_.definition().ValidateThreshold(threshold_);
    index_ = database_.store().MakeIndex();
    // One sort instead of n sorted inserts: a loaded map may hold a million scans.
    if (index_) index_->InsertAll([this](std::size_t i) { return database_.IsValid(i); });
}

LoopQuery LoopDetector::Search(const PreparedQuery& query, std::size_t query_index,
                               const std::function<bool(std::size_t)>& eligible) const {
    const auto k = static_cast<std::size_t>(detector_.top_k);
    const auto search = [&](std::size_t count, const std::function<bool(std::size_t)>& filter) {
        if (index_) return index_->Search(query, count, filter);
        return NearestCandidates(
            database_.size(), count, [&](std::size_t j) { return database_.Distance(query, j); },
            filter);
    };
    LoopQuery result;
    result.query = query_index;
    result.candidates = search(k, eligible);
    Finish(result, detector_.min_gap, database_.times_s(), database_.definition(), threshold_,
           [&](const std::function<bool(std::size_t)>& other_place) {
               return search(1, [&](std::size_t j) { return eligible(j) && other_place(j); });
           });
    return result;
}

void LoopDetector::Verify(LoopQuery& result, const registration::PreparedScan& scan) const {
    if (!detector_.verify || !scan.structure) return;
    VerifyQuery(
        result, scan,
        [this](std::size_t j) -> const registration::PreparedScan& { return scans_[j]; }, detector_,
        database_.method());
}

std::size_t LoopDetector::prepared_bytes() const {
    std::size_t bytes = 0;
    for (const registration::PreparedScan& scan : scans_) bytes += scan.MemoryBytes();
    return bytes;
}

LoopQuery LoopDetector::Process(const core::PointCloud& scan, double time_s) {
    registration::PreparedScan prepared;
    if (detector_.verify)
        prepared = registration::PrepareScan(scan, detector_.verification.reduction);
    return Process(ComputeDescriptor(scan, database_.config()), time_s, std::move(prepared));
}

LoopQuery LoopDetector::Process(const core::Descriptor& descriptor, double time_s,
                                registration::PreparedScan scan) {
    const std::unique_ptr<PreparedQuery> query = database_.Prepare(descriptor);
    const std::size_t query_index = database_.size();
    const auto& times_s = database_.times_s();
    const core::MinGap gap = detector_.min_gap;
    LoopQuery result = Search(*query, query_index, [&](std::size_t j) {
        return j < query_index && database_.IsValid(j) &&
               gap.Allows(query_index, j, time_s, times_s[j]);
    });
    Verify(result, scan);
    database_.Add(descriptor, time_s);
    scans_.push_back(std::move(scan));
    if (index_) index_->Insert(query_index);
    return result;
}

LoopQuery LoopDetector::Query(const core::Descriptor& descriptor,
                              const registration::PreparedScan& scan) const {
    return Query(*database_.Prepare(descriptor), database_.size(), scan);
}

LoopQuery LoopDetector::Query(const PreparedQuery& query, std::size_t query_index,
                              const registration::PreparedScan& scan) const {
    LoopQuery result =
        Search(query, query_index, [&](std::size_t j) { return database_.IsValid(j); });
    Verify(result, scan);
    return result;
}

std::vector<LoopQuery> LocaliseSequence(
    const LoopDetector& map, const DescriptorDatabase& queries, Execution execution,
    const std::vector<registration::PreparedScan>& query_scans) {
    if (queries.config() != map.database().config()) {
        throw core::ConfigError(
            "the query scans were described with another configuration than the map's");
    }
    std::vector<LoopQuery> results(queries.size());
    const auto localise = [&](std::size_t i) {
        results[i].query = i;
        if (!queries.IsValid(i)) return;
        static const registration::PreparedScan kNone;
        results[i] = map.Query(*queries.PrepareStored(i), i,
                               i < query_scans.size() ? query_scans[i] : kNone);
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
                                        const DetectorConfig& detector,
                                        const core::Method& method) {
    detector.Validate();
    const double threshold = detector.ThresholdFor(method);
    MethodOf(method).ValidateThreshold(threshold);
    if (times_s.size() != matrix.size()) {
        throw core::ConfigError("DetectFromMatrix: " + std::to_string(times_s.size()) +
                                " times for " + std::to_string(matrix.size()) + " scans");
    }
    const auto k = static_cast<std::size_t>(detector.top_k);
    std::vector<LoopQuery> results(matrix.size());
    for (std::size_t i = 0; i < matrix.size(); ++i) {
        const auto distance_of = [&](std::size_t j) { return double{matrix.at(i, j)}; };
        const auto eligible = [&](std::size_t j) {
            return j < i && detector.min_gap.Allows(i, j, times_s[i], times_s[j]);
        };
        LoopQuery& result = results[i];
        result.query = i;
        result.candidates = NearestCandidates(i, k, distance_of, eligible);
        Finish(result, detector.min_gap, times_s, MethodOf(method), threshold,
               [&](const std::function<bool(std::size_t)>& other_place) {
                   return NearestCandidates(i, 1, distance_of, [&](std::size_t j) {
                       return eligible(j) && other_place(j);
                   });
               });
    }
    return results;
}

}  // namespace lidarloop::pipeline

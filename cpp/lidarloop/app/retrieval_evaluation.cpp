#include "lidarloop/app/retrieval_evaluation.hpp"

#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::app {

std::vector<eval::QueryCandidates> DescriptorCandidates(
    std::span<const pipeline::LoopQuery> queries, const core::Method& method, double threshold) {
    const pipeline::DescriptorMethod& definition = pipeline::MethodOf(method);
    std::vector<eval::QueryCandidates> result;
    for (const pipeline::LoopQuery& query : queries) {
        if (!query.has_match()) continue;
        eval::QueryCandidates ranked{query.query, {}};
        for (const pipeline::Neighbor& candidate : query.candidates) {
            ranked.ranked.push_back({candidate.index, candidate.distance,
                                     definition.IsMatch(candidate.distance, threshold),
                                     -candidate.distance, std::nullopt});
        }
        result.push_back(std::move(ranked));
    }
    return result;
}

std::vector<eval::QueryCandidates> VerifiedCandidates(
    std::span<const pipeline::LoopQuery> queries) {
    std::vector<eval::QueryCandidates> result;
    for (const pipeline::LoopQuery& query : queries) {
        if (!query.has_match()) continue;
        eval::QueryCandidates ranked{query.query, {}};
        // The evaluation scores each query's first accepted candidate: only the loop the
        // pipeline takes counts as accepted, whatever its rank.
        const std::optional<std::size_t> loop = query.loop();
        for (std::size_t i = 0; i < query.candidates.size(); ++i) {
            const registration::Verification& v = query.verifications.at(i);
            std::optional<core::Transform> pose;
            if (v.accepted) pose = v.T_match_query;
            ranked.ranked.push_back({query.candidates[i].index, query.candidates[i].distance,
                                     loop == i, v.score(), pose});
        }
        result.push_back(std::move(ranked));
    }
    return result;
}

const std::vector<double>& DetectorPathM(const eval::GroundTruth& truth,
                                         const OdometryCheck* odometry) {
    return odometry != nullptr ? odometry->path_m : truth.path_m;
}

pipeline::LoopCheck VerificationCheckOf(const OdometryCheck* odometry,
                                        const pipeline::DetectorConfig& detector,
                                        const PreparedScans* prepared) {
    if (!detector.verify || prepared == nullptr) return {};
    if (odometry == nullptr) return ScansOwnCheck(*prepared, detector.verification.coarse);
    return OdometryLoopCheck(odometry->odometry, odometry->path_m, odometry->config, nullptr,
                             prepared);
}

RetrievalComparison CompareRetrieval(const pipeline::SimilarityMatrix& matrix,
                                     const std::vector<double>& times_s,
                                     const pipeline::DetectorConfig& detector,
                                     const core::Method& method, const eval::GroundTruth& truth,
                                     std::span<const core::StampedPose> poses,
                                     const PreparedScans* prepared,
                                     pipeline::VerificationCache* cache, const Progress& progress,
                                     const OdometryCheck* odometry) {
    return CompareRetrieval(pipeline::DetectFromMatrix(
                                matrix, times_s, detector, method, DetectorPathM(truth, odometry),
                                VerificationCheckOf(odometry, detector, prepared)),
                            detector, method, truth, poses, prepared, cache, progress, odometry);
}

RetrievalComparison CompareRetrieval(std::vector<pipeline::LoopQuery> queries,
                                     const pipeline::DetectorConfig& detector,
                                     const core::Method& method, const eval::GroundTruth& truth,
                                     std::span<const core::StampedPose> poses,
                                     const PreparedScans* prepared,
                                     pipeline::VerificationCache* cache, const Progress& progress,
                                     const OdometryCheck* odometry) {
    RetrievalComparison comparison;
    comparison.top_k = static_cast<std::size_t>(detector.top_k);
    comparison.queries = std::move(queries);
    const eval::LoopRetrievalConfig config{comparison.top_k};
    const std::vector<double>& detector_path_m = DetectorPathM(truth, odometry);
    comparison.descriptor = eval::EvaluateLoopRetrieval(
        DescriptorCandidates(comparison.queries, method, detector.ThresholdFor(method)), truth,
        poses, config, detector_path_m);
    if (!detector.verify || prepared == nullptr) return comparison;
    comparison.verification_times =
        VerifyAll(comparison.queries, *prepared, detector, method, progress, cache,
                  VerificationCheckOf(odometry, detector, prepared));
    comparison.verified = eval::EvaluateLoopRetrieval(VerifiedCandidates(comparison.queries), truth,
                                                      poses, config, detector_path_m);
    return comparison;
}

}  // namespace lidarloop::app

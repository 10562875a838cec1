#pragma once

#include <optional>
#include <span>
#include <vector>

#include "lidarloop/app/progress.hpp"
#include "lidarloop/app/verification_run.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/eval/ground_truth.hpp"
#include "lidarloop/eval/loop_retrieval.hpp"
#include "lidarloop/pipeline/candidate_verification.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

namespace lidarloop::app {

/// The odometry a run's verified loops must agree with (RejectLoopsAgainstOdometry): T_world_sensor
/// and the cumulative path of each scan, and the pose graph's gate.
struct OdometryCheck {
    std::vector<core::StampedPose> odometry;
    std::vector<double> path_m;
    posegraph::PoseGraphConfig config;
};

/// The online detector's view of one method on a sequence (docs/evaluation.md, "Ranked
/// candidates"): every scan's top-k candidates by descriptor distance, scored as the descriptor
/// alone decides them and as geometric verification decides them, on the same ground truth.
struct RetrievalComparison {
    std::size_t top_k = 0;  ///< candidates per query (detection.top_k)
    /// Accepted: a candidate within the method's threshold (W <= tau, sigma' < t_d); score:
    /// -distance. recall_at_k is the ceiling of verification: it cannot find a loop that is
    /// not among the candidates.
    eval::LoopRetrievalEvaluation descriptor;
    /// Accepted: the query's loop (LoopQuery::loop: of the candidates that passed
    /// registration::Verify, the one that overlaps best); score: its overlap. Empty when
    /// verification is off.
    std::optional<eval::LoopRetrievalEvaluation> verified;
    pipeline::VerificationTimes verification_times;  ///< pairs registered by this method's run
    std::vector<pipeline::LoopQuery> queries;        ///< the candidates and their verdicts
};

/// The candidates of `queries` as the descriptor alone decides them: accepted when the
/// distance passes `threshold` under `method`, score -distance.
std::vector<eval::QueryCandidates> DescriptorCandidates(
    std::span<const pipeline::LoopQuery> queries, const core::Method& method, double threshold);

/// The candidates of verified `queries` in descriptor order: accepted only the query's loop
/// (LoopQuery::loop: of the candidates verification accepted, the one that overlaps best), score
/// the verification's overlap (Verification::score), with the registered T_match_query of every
/// accepted candidate.
std::vector<eval::QueryCandidates> VerifiedCandidates(std::span<const pipeline::LoopQuery> queries);

/// The path a detector measures its gap and path rule on: the odometry's when it has one, as
/// `detect --odometry` does; else the ground truth's.
const std::vector<double>& DetectorPathM(const eval::GroundTruth& truth,
                                         const OdometryCheck* odometry);

/// The check `odometry` puts on candidates and loops where a run verifies them
/// (OdometryLoopCheck): detection leaves out the scans it puts out of a loop's reach, and
/// verification rejects the loops it contradicts. Without odometry, prepared->submaps_apart
/// (submaps placed by the scans' neighbours); none without detector.verify or without `prepared`
/// scans. It refers to `odometry`, which must outlive it.
pipeline::LoopCheck VerificationCheckOf(const OdometryCheck* odometry,
                                        const pipeline::DetectorConfig& detector,
                                        const PreparedScans* prepared);

/// Detects the top-k candidates of every scan from `matrix` (pipeline::DetectFromMatrix with
/// `detector`; the gap and path rule on DetectorPathM; with `odometry` and verification, only
/// the scans within its reach, VerificationCheckOf), verifies them when detector.verify (with
/// `prepared`, sharing `cache`, and rejecting what `odometry` contradicts when given), and
/// scores both against `truth` (built from `poses`; revisits by the truth's own path).
RetrievalComparison CompareRetrieval(const pipeline::SimilarityMatrix& matrix,
                                     const std::vector<double>& times_s,
                                     const pipeline::DetectorConfig& detector,
                                     const core::Method& method, const eval::GroundTruth& truth,
                                     std::span<const core::StampedPose> poses,
                                     const PreparedScans* prepared,
                                     pipeline::VerificationCache* cache, const Progress& progress,
                                     const OdometryCheck* odometry = nullptr);

/// CompareRetrieval of queries already detected (e.g. pipeline::DetectStreaming, without the
/// matrix).
RetrievalComparison CompareRetrieval(std::vector<pipeline::LoopQuery> queries,
                                     const pipeline::DetectorConfig& detector,
                                     const core::Method& method, const eval::GroundTruth& truth,
                                     std::span<const core::StampedPose> poses,
                                     const PreparedScans* prepared,
                                     pipeline::VerificationCache* cache, const Progress& progress,
                                     const OdometryCheck* odometry = nullptr);

}  // namespace lidarloop::app

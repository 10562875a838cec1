#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/eval/ground_truth.hpp"
#include "lidarloop/eval/summary.hpp"

namespace lidarloop::eval {

// Scoring of an online loop detector's ranked candidates, with or without geometric
// verification: for every query scan the top-k candidates by descriptor distance, each accepted
// or rejected, with a confidence score and possibly a relative pose. The descriptor alone and
// the verified pipeline are scored by the same functions, so they can be shown side by side.
//
// Zero denominators: unlike metrics.hpp (0, as scikit-learn), a rate whose denominator is 0 is
// NaN here ("undefined"): these are summary numbers compared across pipelines, where a
// precision of 0 with no accepted loop would read as "every loop wrong".

/// One candidate of a query scan, after the pipeline's decision.
struct RankedCandidate {
    /// Scan index of the candidate: an earlier scan outside the minimum gap of the query.
    std::size_t match = 0;
    double distance = 0.0;  ///< descriptor distance (W or sigma'); not NaN, may be +inf
    bool accepted = false;  ///< the pipeline's final decision for this candidate
    /// Confidence, higher = surer; any order-preserving scale. Descriptor only: -distance.
    /// Not NaN (NaN cannot be ranked); use -inf for "no confidence".
    double score = 0.0;
    /// The estimated relative pose, when the pipeline estimated one: maps points of the query
    /// scan into the match scan's frame (metres). Must be finite with a rotation part.
    std::optional<core::Transform> T_match_query;
};

/// The ranked candidates of one query scan.
struct QueryCandidates {
    std::size_t query = 0;                ///< scan index
    std::vector<RankedCandidate> ranked;  ///< best first; no scan twice
};

/// Options of EvaluateLoopRetrieval.
struct LoopRetrievalConfig {
    /// k of recall@k: the first k candidates of each ranked list count. 0 = the length of the
    /// longest list given (the detector's top_k).
    std::size_t recall_k = 0;
    /// An accepted loop's estimated pose is wrong when it is off the true relative pose by more
    /// than this translation (metres) or rotation (degrees): a constraint that would pull a pose
    /// graph out of shape, whether or not the scans count as the same place. > 0.
    double wrong_pose_m = 1.0;
    double wrong_pose_deg = 2.0;

    /// Throws core::ConfigError for a tolerance that is not finite and > 0.
    void Validate() const;
};

/// The error of an estimated relative pose against the true one. With T_est and T_true both
/// T_match_query, the error transform is E = T_true^-1 * T_est: a query point placed by the
/// estimate, mapped back into the query frame by the truth (the identity when exact). E is
/// expressed in the (true) query sensor frame.
struct RelativePoseError {
    double translation_m = 0.0;  ///< |t(E)| = |t_est - t_true|, metres
    double planar_m = 0.0;  ///< |(x, y) of t(E)|, metres: the horizontal part in the query frame
    /// Yaw of E, degrees in [0, 180]: the angle of E's x axis projected on the query frame's
    /// (x, y) plane, as HeadingDifferenceDeg (0 when that axis is vertical).
    double yaw_deg = 0.0;
    double rotation_deg = 0.0;  ///< rotation angle of E (axis-angle), degrees in [0, 180]
};

/// The true relative pose T_match_query = T_world_match^-1 * T_world_query. Thread-safe.
core::Transform TrueRelativePose(const core::Transform& T_world_match,
                                 const core::Transform& T_world_query);

/// The error of `T_match_query_est` against `T_match_query_true` (see RelativePoseError).
/// Thread-safe.
RelativePoseError PoseError(const core::Transform& T_match_query_est,
                            const core::Transform& T_match_query_true);

/// True when `scan` has a ground-truth partner among the scans an online detector can match it
/// to: an earlier scan (smaller index) outside the minimum gap. This is GroundTruth::Overlapping
/// (Magnusson's "overlapping", partners before or after) restricted to earlier partners, the
/// candidates of pipeline::LoopDetector. Throws core::ConfigError for a scan out of range. O(1).
bool Revisiting(const GroundTruth& truth, std::size_t scan);

/// One query's loop: its first accepted candidate in ranked order.
struct AcceptedLoop {
    std::size_t query = 0;
    std::size_t match = 0;
    std::size_t rank = 0;  ///< position in the ranked list, 0 = best
    double score = 0.0;
    bool correct = false;  ///< GroundTruth::IsLoop(query, match)
    /// For loops with an estimated pose (correct or not); nullopt otherwise.
    std::optional<RelativePoseError> pose_error;
    /// The pose error exceeds LoopRetrievalConfig::wrong_pose_m or wrong_pose_deg.
    bool wrong_pose = false;
};

/// The largest recall of the accepted loops at 100 % precision: loops are kept by descending
/// score (score >= threshold) until the first false one. Loops with equal scores cannot be
/// told apart, so a group of equal scores holding a false loop is never kept.
struct FullPrecisionPoint {
    /// true_loops / revisiting scans; NaN without revisiting scans.
    double recall = std::numeric_limits<double>::quiet_NaN();
    std::size_t true_loops = 0;  ///< loops kept (all correct)
    /// The threshold: keep loops with score >= min_score; the lowest kept score. +inf when no
    /// loop can be kept (then true_loops is 0).
    double min_score = std::numeric_limits<double>::infinity();
    /// The highest score of a false loop (-inf when there is none). Every threshold in
    /// (first_false_score, min_score] keeps the same loops (empty when a false loop scores
    /// +inf).
    double first_false_score = -std::numeric_limits<double>::infinity();
};

/// Errors of the correct accepted loops that have an estimated pose (false loops are counted in
/// LoopRetrievalEvaluation::wrong_pose_loops instead: their errors say nothing about accuracy).
struct PoseErrorSummary {
    std::size_t count = 0;  ///< correct accepted loops with T_match_query
    /// Distributions (median, max, ...) of the RelativePoseError fields; nullopt when count
    /// is 0.
    std::optional<Summary> translation_m;
    std::optional<Summary> planar_m;
    std::optional<Summary> yaw_deg;
    std::optional<Summary> rotation_deg;
};

/// Result of EvaluateLoopRetrieval. Counts are numbers of query scans; rates are in [0, 1] or
/// NaN when their denominator is 0.
struct LoopRetrievalEvaluation {
    std::size_t scans = 0;       ///< scans of the ground truth
    std::size_t queries = 0;     ///< queries given (a scan not given has no candidates)
    std::size_t revisiting = 0;  ///< scans for which Revisiting holds: recall denominator
    std::size_t k = 0;           ///< the k of recall@k used (LoopRetrievalConfig::recall_k)

    /// Retrieval, decisions ignored: revisiting queries with a true loop at rank 0 / among the
    /// first k, and their share of `revisiting`.
    std::size_t hits_at_1 = 0;
    std::size_t hits_at_k = 0;
    double recall_at_1 = std::numeric_limits<double>::quiet_NaN();
    double recall_at_k = std::numeric_limits<double>::quiet_NaN();

    /// Decisions: each query's first accepted candidate is its loop (at most one per query).
    /// With GroundTruthConfig::min_path_m, a loop to the same place too little path back is no
    /// revisit and no error: it is in none of these counts (as tools/verified_recall.py strict).
    std::size_t true_loops = 0;   ///< correct loops (necessarily of revisiting queries)
    std::size_t false_loops = 0;  ///< wrong loops, including all of non-revisiting queries
    double precision = std::numeric_limits<double>::quiet_NaN();  ///< true / (true + false)
    double recall = std::numeric_limits<double>::quiet_NaN();     ///< true_loops / revisiting
    /// Loops with an estimated pose, and those whose pose is wrong (AcceptedLoop::wrong_pose):
    /// false loops at a wrong pose, and correct ones registered wrongly. A false loop at the
    /// right pose (the same structure seen from beyond the ground truth's distance) is a sound
    /// constraint and not counted here.
    std::size_t loops_with_pose = 0;
    std::size_t wrong_pose_loops = 0;

    FullPrecisionPoint full_precision;
    PoseErrorSummary pose_error;
    std::vector<AcceptedLoop> loops;  ///< every query's loop, query ascending
};

/// Scores ranked, decided candidates against the ground truth. `poses` are the poses the
/// ground truth was built from (T_world_sensor per scan; only used for pose errors).
///
/// `detector_path_m`: the cumulative path (metres per scan) along which the detector measured a
/// gap in metres, its odometry's (core::CumulativePathM); empty: the ground truth's. Scoring
/// always uses the ground truth's path: an accepted loop within distance_m that the truth does not
/// count as a revisit (too little path back) is neither true nor false.
///
/// Throws core::ConfigError, naming the query and candidate, when: poses.size() != truth.size(); a
/// non-empty detector_path_m does not have truth.size() entries; a query index is out of range
/// or given twice; a candidate is not an earlier scan outside the minimum gap of its query (the
/// gap's unit, on detector_path_m for metres) or appears twice in one list; a distance or score
/// is NaN; a T_match_query is not finite or its linear part is not a rotation (within 1e-4).
/// O(n + C log C) for n scans and C candidates. Thread-safe.
LoopRetrievalEvaluation EvaluateLoopRetrieval(std::span<const QueryCandidates> queries,
                                              const GroundTruth& truth,
                                              std::span<const core::StampedPose> poses,
                                              const LoopRetrievalConfig& config = {},
                                              std::span<const double> detector_path_m = {});

}  // namespace lidarloop::eval

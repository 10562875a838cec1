#include "lidarloop/eval/loop_retrieval.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/core/number_text.hpp"

namespace lidarloop::eval {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
// Largest |R^T R - I| entry accepted for a rotation: loose enough for a pose composed in float.
constexpr double kRotationTolerance = 1e-4;

double Share(std::size_t numerator, std::size_t denominator) {
    return denominator == 0 ? std::numeric_limits<double>::quiet_NaN()
                            : static_cast<double>(numerator) / static_cast<double>(denominator);
}

void CheckTransform(const core::Transform& T, const std::string& where) {
    if (!T.matrix().allFinite()) throw core::ConfigError(where + ": T_match_query is not finite");
    const Eigen::Matrix3d R = T.linear();
    const double off = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (off > kRotationTolerance || R.determinant() <= 0.0) {
        throw core::ConfigError(where + ": the linear part of T_match_query is not a rotation");
    }
}

// Whether the detector may give scan j for query i: outside the gap as the detector measured it,
// along its own path (the odometry's) when the gap is in metres and that path is given.
bool OutsideDetectorGap(const GroundTruth& truth, std::span<const double> detector_path_m,
                        std::size_t i, std::size_t j) {
    const core::MinGap& gap = truth.config.min_gap;
    if (detector_path_m.empty() || gap.unit != core::MinGap::Unit::kMetres)
        return truth.OutsideGap(i, j);
    return i != j && gap.Allows(i, j, detector_path_m[i], detector_path_m[j]);
}

void CheckCandidate(const QueryCandidates& q, std::size_t rank, const GroundTruth& truth,
                    std::span<const double> detector_path_m) {
    const RankedCandidate& c = q.ranked[rank];
    const std::string where = "loop retrieval: query " + std::to_string(q.query) + ", candidate " +
                              std::to_string(rank) + " (scan " + std::to_string(c.match) + ")";
    if (c.match >= truth.size() || c.match >= q.query ||
        !OutsideDetectorGap(truth, detector_path_m, q.query, c.match)) {
        throw core::ConfigError(where + " is not an earlier scan outside the minimum gap");
    }
    if (std::isnan(c.distance)) throw core::ConfigError(where + ": distance is NaN");
    if (std::isnan(c.score)) throw core::ConfigError(where + ": score is NaN");
    if (c.T_match_query) CheckTransform(*c.T_match_query, where);
}

void CheckQuery(const QueryCandidates& q, const GroundTruth& truth,
                std::span<const double> detector_path_m, std::vector<bool>& seen) {
    const std::string where = "loop retrieval: query " + std::to_string(q.query);
    if (q.query >= truth.size()) {
        throw core::ConfigError(where + " is out of range: the ground truth has " +
                                std::to_string(truth.size()) + " scans");
    }
    if (seen[q.query]) throw core::ConfigError(where + " is given twice");
    seen[q.query] = true;
    for (std::size_t rank = 0; rank < q.ranked.size(); ++rank)
        CheckCandidate(q, rank, truth, detector_path_m);
    std::vector<std::size_t> matches;
    for (const auto& c : q.ranked) matches.push_back(c.match);
    std::sort(matches.begin(), matches.end());
    const auto twice = std::adjacent_find(matches.begin(), matches.end());
    if (twice != matches.end()) {
        throw core::ConfigError(where + ": scan " + std::to_string(*twice) +
                                " is a candidate twice");
    }
}

void CheckInput(std::span<const QueryCandidates> queries, const GroundTruth& truth,
                std::span<const core::StampedPose> poses, std::span<const double> detector_path_m) {
    if (poses.size() != truth.size()) {
        throw core::ConfigError("loop retrieval: " + std::to_string(poses.size()) +
                                " poses for a ground truth of " + std::to_string(truth.size()) +
                                " scans");
    }
    if (!detector_path_m.empty() && detector_path_m.size() != truth.size()) {
        throw core::ConfigError("loop retrieval: the detector's path has " +
                                std::to_string(detector_path_m.size()) +
                                " scans, the ground truth " + std::to_string(truth.size()));
    }
    core::CheckPathM(detector_path_m, "loop retrieval: the detector's path");
    std::vector<bool> seen(truth.size(), false);
    for (const auto& q : queries) CheckQuery(q, truth, detector_path_m, seen);
}

// True when a true loop is among the first `k` candidates.
bool HitWithin(const QueryCandidates& q, std::size_t k, const GroundTruth& truth) {
    const std::size_t end = std::min(k, q.ranked.size());
    for (std::size_t rank = 0; rank < end; ++rank) {
        if (truth.IsLoop(q.query, q.ranked[rank].match)) return true;
    }
    return false;
}

std::optional<AcceptedLoop> FirstAccepted(const QueryCandidates& q, const GroundTruth& truth,
                                          std::span<const core::StampedPose> poses,
                                          const LoopRetrievalConfig& config) {
    for (std::size_t rank = 0; rank < q.ranked.size(); ++rank) {
        const RankedCandidate& c = q.ranked[rank];
        if (!c.accepted) continue;
        // The same place too little path back (min_path_m) is no revisit, and no error either.
        const double apart_m = (truth.positions_m[q.query] - truth.positions_m[c.match]).norm();
        if (!truth.Comparable(q.query, c.match) && apart_m < truth.config.distance_m)
            return std::nullopt;
        AcceptedLoop loop{q.query, c.match, rank, c.score, truth.IsLoop(q.query, c.match), {}, {}};
        if (c.T_match_query) {
            loop.pose_error = PoseError(
                *c.T_match_query,
                TrueRelativePose(poses[c.match].T_world_sensor, poses[q.query].T_world_sensor));
            loop.wrong_pose = loop.pose_error->translation_m > config.wrong_pose_m ||
                              loop.pose_error->rotation_deg > config.wrong_pose_deg;
        }
        return loop;
    }
    return std::nullopt;
}

// Keeps loops by descending score, a whole group of equal scores at a time, until a group holds
// a false loop.
FullPrecisionPoint AtFullPrecision(std::vector<AcceptedLoop> loops, std::size_t revisiting) {
    std::sort(loops.begin(), loops.end(),
              [](const AcceptedLoop& a, const AcceptedLoop& b) { return a.score > b.score; });
    FullPrecisionPoint point;
    for (std::size_t begin = 0; begin < loops.size();) {
        std::size_t end = begin;
        bool all_correct = true;
        for (; end < loops.size() && loops[end].score == loops[begin].score; ++end) {
            all_correct = all_correct && loops[end].correct;
        }
        if (!all_correct) {
            point.first_false_score = loops[begin].score;
            break;
        }
        point.true_loops += end - begin;
        point.min_score = loops[begin].score;
        begin = end;
    }
    point.recall = Share(point.true_loops, revisiting);
    return point;
}

PoseErrorSummary SummarizePoseErrors(std::span<const AcceptedLoop> loops) {
    std::vector<double> translation, planar, yaw, rotation;
    for (const auto& loop : loops) {
        if (!loop.pose_error || !loop.correct) continue;
        translation.push_back(loop.pose_error->translation_m);
        planar.push_back(loop.pose_error->planar_m);
        yaw.push_back(loop.pose_error->yaw_deg);
        rotation.push_back(loop.pose_error->rotation_deg);
    }
    PoseErrorSummary summary;
    summary.count = translation.size();
    if (summary.count == 0) return summary;
    summary.translation_m = Summarize(translation);
    summary.planar_m = Summarize(planar);
    summary.yaw_deg = Summarize(yaw);
    summary.rotation_deg = Summarize(rotation);
    return summary;
}

std::size_t LongestList(std::span<const QueryCandidates> queries) {
    std::size_t longest = 0;
    for (const auto& q : queries) longest = std::max(longest, q.ranked.size());
    return longest;
}

}  // namespace

void LoopRetrievalConfig::Validate() const {
    for (const auto& [value, name] :
         {std::pair{wrong_pose_m, "wrong_pose_m"}, std::pair{wrong_pose_deg, "wrong_pose_deg"}}) {
        if (!(std::isfinite(value) && value > 0.0)) {
            throw core::ConfigError(std::string("loop retrieval: ") + name +
                                    " must be a finite number > 0, got " + core::NumberText(value));
        }
    }
}

core::Transform TrueRelativePose(const core::Transform& T_world_match,
                                 const core::Transform& T_world_query) {
    return T_world_match.inverse() * T_world_query;
}

RelativePoseError PoseError(const core::Transform& T_match_query_est,
                            const core::Transform& T_match_query_true) {
    const core::Transform E = T_match_query_true.inverse() * T_match_query_est;
    RelativePoseError error;
    error.translation_m = E.translation().norm();
    error.planar_m = E.translation().head<2>().norm();
    error.yaw_deg = HeadingDifferenceDeg(core::Transform::Identity(), E);
    // Axis-angle via the quaternion (2 atan2(|v|, |w|)): accurate near 0 and 180 degrees, where
    // acos of the trace is not.
    error.rotation_deg = Eigen::AngleAxisd(E.linear()).angle() * kRadToDeg;
    return error;
}

bool Revisiting(const GroundTruth& truth, std::size_t scan) {
    if (scan >= truth.size()) {
        throw core::ConfigError("loop retrieval: scan " + std::to_string(scan) +
                                " is out of range: the ground truth has " +
                                std::to_string(truth.size()) + " scans");
    }
    // The first partner decides (kNoScan, none, is never smaller).
    return truth.first_partner[scan] < scan;
}

LoopRetrievalEvaluation EvaluateLoopRetrieval(std::span<const QueryCandidates> queries,
                                              const GroundTruth& truth,
                                              std::span<const core::StampedPose> poses,
                                              const LoopRetrievalConfig& config,
                                              std::span<const double> detector_path_m) {
    config.Validate();
    CheckInput(queries, truth, poses, detector_path_m);
    LoopRetrievalEvaluation result;
    result.scans = truth.size();
    result.queries = queries.size();
    result.k = config.recall_k == 0 ? LongestList(queries) : config.recall_k;
    for (std::size_t i = 0; i < truth.size(); ++i) result.revisiting += Revisiting(truth, i);
    for (const auto& q : queries) {
        result.hits_at_1 += HitWithin(q, 1, truth);
        result.hits_at_k += HitWithin(q, result.k, truth);
        if (auto loop = FirstAccepted(q, truth, poses, config)) result.loops.push_back(*loop);
    }
    std::sort(result.loops.begin(), result.loops.end(),
              [](const AcceptedLoop& a, const AcceptedLoop& b) { return a.query < b.query; });
    for (const auto& loop : result.loops) {
        (loop.correct ? result.true_loops : result.false_loops)++;
        result.loops_with_pose += loop.pose_error ? 1 : 0;
        result.wrong_pose_loops += loop.wrong_pose ? 1 : 0;
    }
    result.recall_at_1 = Share(result.hits_at_1, result.revisiting);
    result.recall_at_k = Share(result.hits_at_k, result.revisiting);
    result.precision = Share(result.true_loops, result.true_loops + result.false_loops);
    result.recall = Share(result.true_loops, result.revisiting);
    result.full_precision = AtFullPrecision(result.loops, result.revisiting);
    result.pose_error = SummarizePoseErrors(result.loops);
    return result;
}

}  // namespace lidarloop::eval

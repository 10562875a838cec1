#include "lidarloop/registration/verification.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <vector>

#include <Eigen/Eigenvalues>

#include "lidarloop/registration/icp.hpp"

namespace lidarloop::registration {
namespace {

// Ground points a scan needs besides its structure: they fix height, roll and pitch.
constexpr std::size_t kMinGroundPoints = 20;

// A structure point of one scan, moved into the other's frame, lies on the other's surfaces: its
// nearest structure point there is within overlap_radius_m, that point's plane passes within
// overlap_plane_m, and the normals agree.
struct SurfaceHit {
    bool on_surface = false;
    float distance_m = 0.0F;  // to the partner's plane
    Eigen::Vector3f partner_normal;
};

SurfaceHit HitOnSurface(const Eigen::Vector3f& moved, const Eigen::Vector3f& moved_normal,
                        const SurfacePoints& onto, const AcceptanceConfig& config) {
    SurfaceHit hit;
    const auto index =
        onto.grid().NearestWithin(moved, static_cast<float>(config.overlap_radius_m));
    if (index < 0) return hit;
    const auto partner = static_cast<std::size_t>(index);
    hit.partner_normal = onto.normals()[partner];
    hit.distance_m = hit.partner_normal.dot(moved - onto.points()[partner]);
    hit.on_surface = std::abs(hit.distance_m) <= config.overlap_plane_m &&
                     std::abs(hit.partner_normal.dot(moved_normal)) >= kOverlapMinNormalCosine;
    return hit;
}

bool InView(const Eigen::Vector3f& point, const Eigen::Vector3f& moved, float range_m) {
    return point.norm() <= range_m && moved.norm() <= range_m;
}

struct OneWay {
    std::size_t in_view = 0;
    std::size_t overlapping = 0;
    std::size_t distinctive_in_view = 0;
    std::size_t distinctive_overlapping = 0;
    double squared_sum_m2 = 0.0;
    std::vector<std::uint32_t> overlapping_points;        // indices in `from`
    std::vector<Eigen::Vector2f> overlapping_partner_xy;  // horizontal part of partner normals
};

OneWay OverlapOneWay(const SurfacePoints& from, const std::vector<std::uint8_t>& distinctive,
                     const SurfacePoints& onto, const Eigen::Isometry3f& T_onto_from,
                     const AcceptanceConfig& config, bool keep_points, std::size_t stride = 1) {
    OneWay result;
    const auto range_m = static_cast<float>(config.overlap_range_m);
    for (std::size_t i = 0; i < from.size(); i += stride) {
        const Eigen::Vector3f moved = T_onto_from * from.points()[i];
        if (!InView(from.points()[i], moved, range_m)) continue;
        const bool is_distinctive = i < distinctive.size() && distinctive[i] != 0;
        ++result.in_view;
        result.distinctive_in_view += is_distinctive ? 1 : 0;
        const SurfaceHit hit =
            HitOnSurface(moved, T_onto_from.linear() * from.normals()[i], onto, config);
        if (!hit.on_surface) continue;
        ++result.overlapping;
        result.distinctive_overlapping += is_distinctive ? 1 : 0;
        result.squared_sum_m2 += static_cast<double>(hit.distance_m) * hit.distance_m;
        if (keep_points) {
            result.overlapping_points.push_back(static_cast<std::uint32_t>(i));
            result.overlapping_partner_xy.push_back(hit.partner_normal.head<2>());
        }
    }
    return result;
}

double Fraction(std::size_t part, std::size_t whole) {
    return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
}

// Given the query's side, `forward`, whether both sides overlap at least `min_overlap` (the
// match's side measured only when the query's reaches it).
bool BothWaysReach(const PreparedScan& query, const PreparedScan& match,
                   const Eigen::Isometry3f& T_match_query, const OneWay& forward,
                   const AcceptanceConfig& config, double min_overlap, std::size_t stride) {
    if (Fraction(forward.overlapping, forward.in_view) < min_overlap) return false;
    const OneWay backward =
        OverlapOneWay(*match.structure, match.structure_distinctive, *query.structure,
                      T_match_query.inverse(), config, false, stride);
    return Fraction(backward.overlapping, backward.in_view) >= min_overlap;
}

// The horizontal direction the overlapping surfaces constrain least: the eigenvector of the
// smallest eigenvalue of the sum of n n^T over their horizontal normals.
Eigen::Vector2d WeakestDirection(const std::vector<Eigen::Vector2f>& normals_xy) {
    Eigen::Matrix2d information = Eigen::Matrix2d::Zero();
    for (const auto& n : normals_xy) information += n.cast<double>() * n.cast<double>().transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(information);
    return solver.eigenvectors().col(0);  // eigenvalues ascending
}

// The overlapping query points whose surfaces face d by at least `min_facing` (|n . d|).
std::vector<std::uint32_t> PointsFacing(const OneWay& forward, const Eigen::Vector2f& d,
                                        float min_facing) {
    std::vector<std::uint32_t> facing;
    for (std::size_t k = 0; k < forward.overlapping_points.size(); ++k) {
        if (std::abs(forward.overlapping_partner_xy[k].dot(d)) >= min_facing)
            facing.push_back(forward.overlapping_points[k]);
    }
    return facing;
}

// Shifted by degeneracy_shift_m along d both ways, the share of `points` still on a surface, the
// larger of the two; 1 when there are none.
double ShiftedOverlapRatio(const SurfacePoints& query, const SurfacePoints& match,
                           const Eigen::Isometry3f& T_match_query, const Eigen::Vector2f& d,
                           const std::vector<std::uint32_t>& points,
                           const AcceptanceConfig& config) {
    if (points.empty()) return 1.0;
    double worst = 0.0;
    for (const float sign : {-1.0F, 1.0F}) {
        Eigen::Isometry3f shifted = T_match_query;
        shifted.translation().head<2>() += sign * static_cast<float>(config.degeneracy_shift_m) * d;
        std::size_t still = 0;
        for (const std::uint32_t i : points) {
            const Eigen::Vector3f moved = shifted * query.points()[i];
            still +=
                HitOnSurface(moved, shifted.linear() * query.normals()[i], match, config).on_surface
                    ? 1
                    : 0;
        }
        worst = std::max(worst, Fraction(still, points.size()));
    }
    return worst;
}

// The degeneracy test (docs/verification.md): the overlapping query points whose surfaces face
// the weakest direction pin the position along it; shifted along it, most must stop fitting.
// They are those within 60 degrees of it; where the odometry judges the pose and those are too
// few, every point the shift moves off its plane (SlantThatAShiftBreaks).
void MeasureDegeneracy(const SurfacePoints& query, const SurfacePoints& match,
                       const Eigen::Isometry3f& T_match_query, const OneWay& forward,
                       const AcceptanceConfig& config, bool odometry_judges, Overlap& overlap) {
    overlap.weakest_direction = WeakestDirection(forward.overlapping_partner_xy);
    const Eigen::Vector2f d = overlap.weakest_direction.cast<float>();
    std::vector<std::uint32_t> constraining = PointsFacing(forward, d, kFacingWithin60Degrees);
    if (odometry_judges && constraining.size() < MinConstrainingPoints(config, true)) {
        constraining = PointsFacing(forward, d, static_cast<float>(SlantThatAShiftBreaks(config)));
    }
    overlap.constraining_points = constraining.size();
    overlap.shifted_overlap_ratio =
        ShiftedOverlapRatio(query, match, T_match_query, d, constraining, config);
}

core::Transform PlanarPose(const PlanarHypothesis& hypothesis) {
    core::Transform pose = core::Transform::Identity();
    pose.linear() =
        Eigen::AngleAxisd(hypothesis.yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pose.translation() << hypothesis.translation_m, 0.0;
    return pose;
}

// How far from the query's sensor a coarse peak may put the match's and still be refined
// (CoarseConfig::max_peak_beyond_loop_m): from farther, ICP ends `too_far`.
double LoopReachM(const VerificationConfig& config) {
    return config.acceptance.max_loop_distance_m + config.coarse.max_peak_beyond_loop_m;
}

// The hypotheses ICP refines, best first: of the first CoarseConfig::hypotheses, those whose
// score reaches min_hypothesis_score_ratio of the best's (the best's, in reach or not) and that
// lie within a loop's reach.
std::vector<std::size_t> Refinable(const std::vector<PlanarHypothesis>& hypotheses,
                                   const VerificationConfig& config) {
    const auto tried =
        std::min(hypotheses.size(), static_cast<std::size_t>(config.coarse.hypotheses));
    const double min_score = config.coarse.min_hypothesis_score_ratio * hypotheses.front().score;
    std::vector<std::size_t> refinable;
    for (std::size_t i = 0; i < tried; ++i) {
        if (i > 0 && hypotheses[i].score < min_score) break;  // scores descend
        if (hypotheses[i].translation_m.norm() <= LoopReachM(config)) refinable.push_back(i);
    }
    return refinable;
}

bool TooFewPoints(const PreparedScan& scan, const AcceptanceConfig& config) {
    return !scan.structure || !scan.ground ||
           scan.structure->size() < static_cast<std::size_t>(config.min_overlapping_points) ||
           scan.ground->size() < kMinGroundPoints;
}

}  // namespace

double AllowedRmse(const PreparedScan& query, const PreparedScan& match,
                   const AcceptanceConfig& config, bool odometry_judges) {
    // The RMS of the two scans' own residuals: what a right pose leaves between them.
    const double roughness_m =
        std::sqrt(0.5 * (query.structure_roughness_m * query.structure_roughness_m +
                         match.structure_roughness_m * match.structure_roughness_m));
    const double ratio =
        odometry_judges ? config.max_rmse_ratio_with_odometry : config.max_rmse_ratio;
    return std::clamp(ratio * roughness_m, config.min_allowed_rmse_m, config.max_rmse_m);
}

double OverlapLowerBound(std::size_t overlapping, std::size_t in_view, double z) {
    if (in_view == 0) return 0.0;
    // Wilson's score interval of a binomial share, its lower end.
    const double n = static_cast<double>(in_view);
    const double share = static_cast<double>(overlapping) / n;
    const double z2_n = z * z / n;
    const double centre = share + 0.5 * z2_n;
    const double half = z * std::sqrt(share * (1.0 - share) / n + 0.25 * z2_n / n);
    return std::max(0.0, (centre - half) / (1.0 + z2_n));
}

bool EnoughOverlappingPoints(std::size_t overlapping, std::size_t in_view,
                             const AcceptanceConfig& config) {
    if (overlapping >= static_cast<std::size_t>(config.min_overlapping_points)) return true;
    return config.overlap_confidence_z > 0.0 &&
           OverlapLowerBound(overlapping, in_view, config.overlap_confidence_z) >=
               config.min_overlap;
}

namespace {

// The first acceptance rule the registered pair breaks (kNone: none). `odometry_judges`: the
// odometry's gate judges the pose: fewer points need to pin it, and it may fit a little worse.
RejectReason Judge(const PreparedScan& query, const PreparedScan& match,
                   const Verification& verification, bool converged, const AcceptanceConfig& config,
                   bool odometry_judges) {
    const Overlap& overlap = verification.overlap;
    if (!converged) return RejectReason::kNotConverged;
    if (!EnoughOverlappingPoints(overlap.query_overlapping, overlap.query_in_view, config) ||
        !EnoughOverlappingPoints(overlap.match_overlapping, overlap.match_in_view, config) ||
        overlap.Min() < config.min_overlap ||
        overlap.MinDistinctive() < config.min_distinctive_overlap) {
        return RejectReason::kLowOverlap;
    }
    if (overlap.rmse_m > AllowedRmse(query, match, config, odometry_judges)) {
        return RejectReason::kHighRmse;
    }
    if (overlap.constraining_points < MinConstrainingPoints(config, odometry_judges) ||
        overlap.shifted_overlap_ratio > config.max_shifted_overlap_ratio) {
        return RejectReason::kDegenerate;
    }
    return RejectReason::kNone;
}

// The abandonment check reads every 4th structure point: it only has to tell hopeless poses
// (overlap under 0.15) from the rest, and at 750 points a side the estimate is within about 0.02
// of the full count; it was a tenth of verification time (docs/verification.md).
constexpr std::size_t kAbandonCheckStride = 4;

// Two registered poses that are the same solution: within 1 m and 5 degrees.
bool SamePose(const core::Transform& a, const core::Transform& b) {
    const core::Transform difference = a.inverse() * b;
    return difference.translation().norm() < 1.0 &&
           Eigen::AngleAxisd(difference.linear()).angle() < 5.0 * std::numbers::pi / 180.0;
}

// How freely the first stage's pose slides: shifted along the direction the overlapping points
// of `forward` (the query's side, its points kept) constrain least, the share of those facing it
// that still fit (1 when none face it).
double SlidingShare(const PreparedScan& query, const PreparedScan& match,
                    const Eigen::Isometry3f& T_match_query, const OneWay& forward,
                    const AcceptanceConfig& config) {
    const Eigen::Vector2f d = WeakestDirection(forward.overlapping_partner_xy).cast<float>();
    const std::vector<std::uint32_t> facing = PointsFacing(forward, d, kFacingWithin60Degrees);
    return ShiftedOverlapRatio(*query.structure, *match.structure, T_match_query, d, facing,
                               config);
}

// ICP from `initial` with `icp`, abandoned after its first stage when the pose overlaps too
// little to ever pass (IcpConfig::abandon_below_overlap), when it slides and `slid` is given
// (IcpConfig::abandon_above_shifted_overlap; `*slid` gets the share) or, searching for a rival of
// the `accepted` pose, when it has come to that pose: the later stages only refine toward it
// (docs/verification.md, "No half-way rivals").
IcpResult Refine(const PreparedScan& query, const PreparedScan& match,
                 const core::Transform& initial, const VerificationConfig& config,
                 const IcpConfig& icp,
                 const std::optional<core::Transform>& accepted = std::nullopt,
                 std::optional<double>* slid = nullptr) {
    return RefinePointToPlane(
        query, match, initial, icp, [&](const core::Transform& T_match_query) {
            if (accepted && SamePose(T_match_query, *accepted)) return false;
            // The overlap check and the slide check read one pass over every 4th query point.
            const bool slide_check =
                slid != nullptr && config.icp.abandon_above_shifted_overlap < 1.0;
            const Eigen::Isometry3f T = T_match_query.cast<float>();
            const OneWay forward =
                OverlapOneWay(*query.structure, query.structure_distinctive, *match.structure, T,
                              config.acceptance, slide_check, kAbandonCheckStride);
            if (!BothWaysReach(query, match, T, forward, config.acceptance,
                               config.icp.abandon_below_overlap, kAbandonCheckStride))
                return false;
            if (slide_check) {
                const double share = SlidingShare(query, match, T, forward, config.acceptance);
                if (share > config.icp.abandon_above_shifted_overlap) {
                    *slid = share;
                    return false;
                }
            }
            return true;
        });
}

// ICP from one coarse hypothesis, then the acceptance rule.
Verification RegisterFrom(const PreparedScan& query, const PreparedScan& match,
                          const PlanarHypothesis& hypothesis, const VerificationConfig& config,
                          bool odometry_judges) {
    // Where the odometry judges, its looser degeneracy test decides at the end.
    std::optional<double> slid;
    const IcpResult icp = Refine(query, match, PlanarPose(hypothesis), config, config.icp,
                                 std::nullopt, odometry_judges ? nullptr : &slid);
    Verification result;
    result.T_match_query = icp.T_match_query;
    result.overlap =
        MeasureOverlap(query, match, icp.T_match_query, config.acceptance, odometry_judges);
    // The share that dropped it, not the full test's at that unfinished pose.
    if (slid) result.overlap.shifted_overlap_ratio = *slid;
    result.coarse_score = hypothesis.score;
    result.icp_iterations = icp.iterations;
    result.shifted_overlap_ratio = result.overlap.shifted_overlap_ratio;
    result.reason = slid            ? RejectReason::kDegenerate
                    : icp.abandoned ? RejectReason::kLowOverlap
                                    : Judge(query, match, result, icp.converged, config.acceptance,
                                            odometry_judges);
    result.accepted = result.reason == RejectReason::kNone;
    return result;
}

// Whether a pose other than the accepted one also fits: ICP from every other hypothesis, and a
// rival is a different pose whose overlap reaches max_rival_overlap_ratio of the accepted one
// within the allowed RMSE. Periodic places (rows of trees, identical corridors) have rivals. A
// pose that `allowed` (the odometry) rules out is none: it will not be the loop. Its ICP takes
// longer steps along a sliding direction (IcpConfig::rival_step_factor), so that a pose half-way
// to the accepted one along a road is not taken for a rival.
bool HasRivalPose(const PreparedScan& query, const PreparedScan& match,
                  const std::vector<PlanarHypothesis>& hypotheses, std::size_t accepted_index,
                  const Verification& accepted, const VerificationConfig& config,
                  const PoseAllowed& allowed) {
    IcpConfig toward_rival = config.icp;
    toward_rival.aligned_step_factor = config.icp.rival_step_factor;
    // Every point from the start: with the thinner first stage and its longer steps, the other
    // peaks of four true Livox pairs settled at poses that passed for rivals.
    toward_rival.first_stage_structure_points = config.icp.max_structure_points;
    toward_rival.first_stage_ground_points = config.icp.max_ground_points;
    for (std::size_t j = 0; j < hypotheses.size(); ++j) {
        if (j == accepted_index) continue;
        const IcpResult icp = Refine(query, match, PlanarPose(hypotheses[j]), config, toward_rival,
                                     accepted.T_match_query);
        if (icp.abandoned || SamePose(icp.T_match_query, accepted.T_match_query)) continue;
        if (allowed && !allowed(icp.T_match_query)) continue;
        const Overlap overlap = MeasureOverlap(query, match, icp.T_match_query, config.acceptance);
        if (overlap.Min() >= config.acceptance.max_rival_overlap_ratio * accepted.overlap.Min() &&
            overlap.rmse_m <= AllowedRmse(query, match, config.acceptance)) {
            return true;
        }
    }
    return false;
}

}  // namespace

std::string ToString(RejectReason reason) {
    switch (reason) {
        case RejectReason::kNone:
            return "none";
        case RejectReason::kTooFewPoints:
            return "too_few_points";
        case RejectReason::kNoAlignment:
            return "no_alignment";
        case RejectReason::kNotConverged:
            return "not_converged";
        case RejectReason::kLowOverlap:
            return "low_overlap";
        case RejectReason::kHighRmse:
            return "high_rmse";
        case RejectReason::kDegenerate:
            return "degenerate";
        case RejectReason::kAmbiguous:
            return "ambiguous";
        case RejectReason::kTooFar:
            return "too_far";
        case RejectReason::kPruned:
            return "pruned";
        case RejectReason::kOdometryMismatch:
            return "odometry_mismatch";
        case RejectReason::kNotNeeded:
            return "not_needed";
        case RejectReason::kUnlikeNeighbours:
            return "unlike_neighbours";
        case RejectReason::kUnlikeRevisit:
            return "unlike_revisit";
        case RejectReason::kUnlikeFits:
            return "unlike_fits";
        case RejectReason::kUnlikeMotion:
            return "unlike_motion";
    }
    return "unknown";
}

double SlantThatAShiftBreaks(const AcceptanceConfig& config) {
    return config.overlap_plane_m / config.degeneracy_shift_m;
}

std::size_t MinConstrainingPoints(const AcceptanceConfig& config, bool odometry_judges) {
    return static_cast<std::size_t>(odometry_judges ? config.min_constraining_points_with_odometry
                                                    : config.min_constraining_points);
}

Overlap MeasureOverlap(const PreparedScan& query, const PreparedScan& match,
                       const core::Transform& T_match_query, const AcceptanceConfig& config,
                       bool odometry_judges) {
    const Eigen::Isometry3f T = T_match_query.cast<float>();
    const OneWay forward = OverlapOneWay(*query.structure, query.structure_distinctive,
                                         *match.structure, T, config, true);
    const OneWay backward = OverlapOneWay(*match.structure, match.structure_distinctive,
                                          *query.structure, T.inverse(), config, false);
    Overlap overlap;
    overlap.query_fraction = Fraction(forward.overlapping, forward.in_view);
    overlap.match_fraction = Fraction(backward.overlapping, backward.in_view);
    overlap.query_distinctive_fraction =
        Fraction(forward.distinctive_overlapping, forward.distinctive_in_view);
    overlap.match_distinctive_fraction =
        Fraction(backward.distinctive_overlapping, backward.distinctive_in_view);
    overlap.query_overlapping = forward.overlapping;
    overlap.match_overlapping = backward.overlapping;
    overlap.query_in_view = forward.in_view;
    overlap.match_in_view = backward.in_view;
    const std::size_t both = forward.overlapping + backward.overlapping;
    overlap.rmse_m = both == 0 ? 0.0
                               : std::sqrt((forward.squared_sum_m2 + backward.squared_sum_m2) /
                                           static_cast<double>(both));
    MeasureDegeneracy(*query.structure, *match.structure, T, forward, config, odometry_judges,
                      overlap);
    return overlap;
}

bool OverlapReaches(const PreparedScan& query, const PreparedScan& match,
                    const core::Transform& T_match_query, const AcceptanceConfig& config,
                    double min_overlap, std::size_t stride) {
    const Eigen::Isometry3f T = T_match_query.cast<float>();
    const OneWay forward = OverlapOneWay(*query.structure, query.structure_distinctive,
                                         *match.structure, T, config, false, stride);
    return BothWaysReach(query, match, T, forward, config, min_overlap, stride);
}

Verification Verify(const PreparedScan& query, const CoarseQuery& coarse, const PreparedScan& match,
                    const VerificationConfig& config, const PoseAllowed& allowed,
                    const YawWindow& yaws) {
    Verification best;
    if (TooFewPoints(query, config.acceptance) || TooFewPoints(match, config.acceptance)) {
        best.reason = RejectReason::kTooFewPoints;
        return best;
    }
    const auto hypotheses = CoarseAlign(coarse, *match.structure, yaws);
    if (hypotheses.empty()) {
        best.reason = RejectReason::kNoAlignment;
        return best;
    }
    // Hypotheses in order of coarse score; the first that passes is the answer unless another
    // fits about as well, else the one that overlapped best explains the rejection.
    best.reason = RejectReason::kTooFar;  // when every peak is out of reach
    int refined = 0;
    for (const std::size_t i : Refinable(hypotheses, config)) {
        Verification trial =
            RegisterFrom(query, match, hypotheses[i], config, static_cast<bool>(allowed));
        trial.registered_hypotheses = ++refined;
        if (trial.accepted) {
            if (trial.T_match_query.translation().norm() > config.acceptance.max_loop_distance_m) {
                trial.accepted = false;
                trial.reason = RejectReason::kTooFar;
            } else if (HasRivalPose(query, match, hypotheses, i, trial, config, allowed)) {
                trial.accepted = false;
                trial.reason = RejectReason::kAmbiguous;
            }
            return trial;
        }
        if (refined == 1 || trial.overlap.Min() > best.overlap.Min()) best = trial;
        best.registered_hypotheses = refined;
    }
    return best;
}

Verification VerifyPair(const core::PointCloud& query, const core::PointCloud& match,
                        const VerificationConfig& config) {
    config.Validate();
    const PreparedScan prepared_query = PrepareScan(query, config.reduction);
    const PreparedScan prepared_match = PrepareScan(match, config.reduction);
    const CoarseQuery coarse(*prepared_query.structure, config.coarse);
    return Verify(prepared_query, coarse, prepared_match, config);
}

}  // namespace lidarloop::registration

#pragma once

#include <cstddef>
#include <functional>
#include <limits>
#include <string>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/registration/coarse_alignment.hpp"
#include "lidarloop/registration/prepared_scan.hpp"
#include "lidarloop/registration/verification_config.hpp"

namespace lidarloop::registration {

/// Why a candidate was not accepted (kNone: it was).
enum class RejectReason {
    kNone,
    kTooFewPoints,  ///< a scan has too few structure or ground points to register
    kNoAlignment,   ///< the coarse search found no overlap of the two scans at any pose
    kNotConverged,  ///< ICP did not settle
    kLowOverlap,    ///< too few structure points of one scan lie on the other's surfaces
    kHighRmse,      ///< the overlapping points sit too far from the other scan's planes
    kDegenerate,    ///< sliding along the weakest direction fits as well (street, corridor)
    kAmbiguous,     ///< another, distinct pose fits about as well (periodic structure)
    /// the sensors are farther apart than one place: registered so, or (not registered) every
    /// coarse peak that could be refined put them farther than a loop's distance plus
    /// CoarseConfig::max_peak_beyond_loop_m
    kTooFar,
    kPruned,  ///< not registered: the descriptor distance failed the threshold set
    /// registered, but the odometry puts the two scans elsewhere beyond its drift (detect with
    /// odometry: the pose graph's gate, posegraph::GateAgainstOdometry)
    kOdometryMismatch,
    /// not registered: a candidate ranked higher is the query's loop (detection.stop_at_first_loop)
    kNotNeeded,
    /// registered, but it overlaps far less than its scans do with their neighbours in the
    /// sequence (AcceptanceConfig::min_neighbour_overlap_ratio; without odometry)
    kUnlikeNeighbours,
    /// registered, but with the odometry a longer chain of agreeing loops of its revisit (queries
    /// and matches within AcceptanceConfig::revisit_path_m of path) places it elsewhere (offline:
    /// detect, evaluate, optimise; pipeline::RejectLoopsUnlikeTheirRevisit)
    kUnlikeRevisit,
    /// registered and passing, but with the odometry more of the query's fits on candidates
    /// ranked before it place the query elsewhere than agree with it
    /// (pipeline::RejectLoopsUnlikeEarlierFits)
    kUnlikeFits,
    /// registered, but without odometry the scans between match and query, each registered to
    /// the one before, put the two too far apart for a loop (AcceptanceConfig::motion_*;
    /// pipeline::MotionRulesOutLoop)
    kUnlikeMotion,
};

/// "none", "too_few_points", "no_alignment", "not_converged", "low_overlap", "high_rmse",
/// "degenerate", "ambiguous", "too_far", "pruned", "odometry_mismatch", "not_needed",
/// "unlike_neighbours", "unlike_revisit", "unlike_fits", "unlike_motion": the spelling of loops.csv
/// and `lidarloop verify`.
std::string ToString(RejectReason reason);

/// How well a query sits on a match at a pose (registration::MeasureOverlap).
struct Overlap {
    double query_fraction = 0.0;  ///< query structure points on match surfaces / those in view
    double match_fraction = 0.0;  ///< the same, the other way
    /// The same over the distinctive structure points only (PreparedScan::structure_distinctive).
    double query_distinctive_fraction = 0.0;
    double match_distinctive_fraction = 0.0;
    std::size_t query_overlapping = 0;
    std::size_t match_overlapping = 0;
    std::size_t query_in_view = 0;  ///< query structure points in view of both sensors
    std::size_t match_in_view = 0;  ///< the same, the other way
    double rmse_m = 0.0;            ///< RMS plane distance of the overlapping points, both ways
    /// Horizontal direction (match frame) the overlapping structure constrains least.
    Eigen::Vector2d weakest_direction = Eigen::Vector2d::UnitX();
    /// Overlapping query points whose surfaces face the weakest direction (they pin it;
    /// kFacingWithin60Degrees, or SlantThatAShiftBreaks where the odometry judges the pose).
    std::size_t constraining_points = 0;
    /// Share of those still on a surface after shifting by degeneracy_shift_m along the weakest
    /// direction (the worse sign); 1 when there are none.
    double shifted_overlap_ratio = 1.0;

    double Min() const { return std::min(query_fraction, match_fraction); }
    double MinDistinctive() const {
        return std::min(query_distinctive_fraction, match_distinctive_fraction);
    }
};

/// The verdict on one candidate pair.
struct Verification {
    bool accepted = false;
    RejectReason reason = RejectReason::kNone;
    core::Transform T_match_query = core::Transform::Identity();  ///< query -> match frame
    Overlap overlap;
    /// overlap.shifted_overlap_ratio of the registered pose; NaN when not registered.
    double shifted_overlap_ratio = std::numeric_limits<double>::quiet_NaN();
    double coarse_score = 0.0;  ///< the coarse correlation of the chosen hypothesis
    int icp_iterations = 0;
    /// Coarse hypotheses ICP refined before the verdict (CoarseConfig::hypotheses at most, fewer
    /// after an acceptance, below min_hypothesis_score_ratio or out of a loop's reach), rival
    /// poses not counted. 0: not registered.
    int registered_hypotheses = 0;
    /// Whether ICP refined some hypothesis: only then do the pose and fit fields hold a result.
    bool Registered() const { return registered_hypotheses > 0; }
    /// Confidence for ranking accepted loops: the smaller overlap fraction (0 when rejected
    /// before registration).
    double score() const { return overlap.Min(); }
};

/// The overlap of `query` on `match` at T_match_query (see AcceptanceConfig), its degeneracy
/// measured as the acceptance rule does where `odometry_judges` says (Verify). Thread-safe.
Overlap MeasureOverlap(const PreparedScan& query, const PreparedScan& match,
                       const core::Transform& T_match_query, const AcceptanceConfig& config,
                       bool odometry_judges = false);

/// The degeneracy test counts a point as pinning the position along the weakest direction d when
/// its surface faces d within 60 degrees (|n . d| >= 0.5).
inline constexpr float kFacingWithin60Degrees = 0.5F;

/// The smallest |n . d| at which a shift by degeneracy_shift_m along d moves a point off its plane
/// by more than overlap_plane_m (0.3 / 2 = 0.15: normals within 81 degrees of d). Where the
/// odometry judges the pose and fewer than its floor of points face d within 60 degrees, such
/// slanted points pin it too (docs/verification.md, "Slanted surfaces pin the road").
double SlantThatAShiftBreaks(const AcceptanceConfig& config);

/// The degeneracy test's floor: min_constraining_points, or the odometry's where it judges.
std::size_t MinConstrainingPoints(const AcceptanceConfig& config, bool odometry_judges);

/// MeasureOverlap(query, match, T_match_query, config).Min() >= min_overlap, computed without
/// the degeneracy test and without the match side when the query side already falls short (the
/// check that abandons an ICP hypothesis). With `stride` > 1 it counts every stride-th structure
/// point of each side only: an estimate, cheaper by that factor. Thread-safe.
bool OverlapReaches(const PreparedScan& query, const PreparedScan& match,
                    const core::Transform& T_match_query, const AcceptanceConfig& config,
                    double min_overlap, std::size_t stride = 1);

/// The largest RMSE a pair may have: max_rmse_ratio (max_rmse_ratio_with_odometry where
/// `odometry_judges`) times the RMS of the two scans' roughness
/// (PreparedScan::structure_roughness_m: how well each fits itself), within
/// [min_allowed_rmse_m, max_rmse_m].
double AllowedRmse(const PreparedScan& query, const PreparedScan& match,
                   const AcceptanceConfig& config, bool odometry_judges = false);

/// The lower end of the Wilson score interval (`z` standard errors) of the share `overlapping` /
/// `in_view`: how low the share of a pair's structure points on the other scan's surfaces may
/// truly be, given how few of them the scans show. 0 when none is in view.
double OverlapLowerBound(std::size_t overlapping, std::size_t in_view, double z);

/// Whether `overlapping` of the `in_view` structure points are enough evidence, one way: at
/// least min_overlapping_points, or fewer whose share stays at least min_overlap at its lower
/// bound (OverlapLowerBound, overlap_confidence_z; never when that is 0).
bool EnoughOverlappingPoints(std::size_t overlapping, std::size_t in_view,
                             const AcceptanceConfig& config);

/// Whether another source of the pose, the odometry's gate, allows T_match_query for a loop of
/// two scans (app::OdometryLoopCheck). Empty where no such source judges the pair.
using PoseAllowed = std::function<bool(const core::Transform& T_match_query)>;

/// Registers one candidate to its query without a prior pose (coarse search, ICP from the best
/// hypotheses within a loop's reach, the first accepted or else the best overlap wins) and
/// decides by AcceptanceConfig. `coarse` must be built from `query` with config.coarse. Never
/// throws on bad data: degenerate input is a rejection with its reason. Thread-safe.
/// Given `allowed` (the odometry judges the loop's pose and will reject what it does not allow),
/// the degeneracy test asks for acceptance.min_constraining_points_with_odometry points instead of
/// min_constraining_points, the RMSE may reach max_rmse_ratio_with_odometry, and only a rival pose
/// it allows makes the place ambiguous (docs/verification.md, "The odometry pins the road").
/// Given `yaws` (the yaws the odometry's gate allows, or without odometry those the layouts
/// suggest), the coarse search looks there only (CoarseAlign): `coarse` must have been built
/// with it among its windows.
Verification Verify(const PreparedScan& query, const CoarseQuery& coarse, const PreparedScan& match,
                    const VerificationConfig& config, const PoseAllowed& allowed = {},
                    const YawWindow& yaws = {});

/// The same for two raw scans (sensor frames, metres): prepares both, then verifies. Validates
/// `config` (core::ConfigError).
Verification VerifyPair(const core::PointCloud& query, const core::PointCloud& match,
                        const VerificationConfig& config);

}  // namespace lidarloop::registration

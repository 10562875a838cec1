#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/pipeline/descriptor_database.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"
#include "lidarloop/pipeline/expanded_scans.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"
#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/verification.hpp"

namespace lidarloop::pipeline {

class NeighbourOverlaps;

/// How loop candidates are chosen and decided.
struct DetectorConfig {
    /// S: a scan's candidates are the scans at least this far back (Magnusson II-E).
    core::MinGap min_gap;
    /// And more than this much path back, metres, wherever the path is known (the odometry, else
    /// the poses): a loop worth having removes the drift of a long path, and on a slow platform
    /// the gap alone lets the recent past crowd out the revisits (docs/cli.md, "Run options"). 0:
    /// no path rule. Evaluation counts revisits by the same rule.
    double min_path_m = 50.0;
    /// Candidates reported (and verified) per query, nearest first; 1..1000. 10: on the demo
    /// sequence range has a true loop among its top 5 for 89 % of the revisiting scans and its
    /// top 10 for 96 % (docs/verification.md); on real data 85 % at 10 (issue 14).
    int top_k = 10;
    /// Where the odometry judges the loops (a LoopCheck with view_distance_m: `detect` and
    /// `evaluate` with --odometry, the online detector with a gate, when they verify): the top_k
    /// are the scans among this many best-ranked ones within the odometry's reach whose view
    /// centres the odometry puts nearest the query's, nearest first (at most top_k: the top_k
    /// best-ranked within reach, still nearest first). 1..1000. 50: chosen on the seed-3 simulated
    /// drives and the real HKU_1, validated on the seed-7 drives and HKU_2 (docs/verification.md,
    /// "The odometry orders the shortlist").
    int odometry_shortlist = 50;
    /// Where the scans are verified and no odometry orders them (a LoopCheck with
    /// layout_similarity): the top_k are the scans among this many best-ranked ones whose layouts
    /// are most alike the query's (registration::LayoutSimilarity), most alike first. 0: rank
    /// order; else 1..1000. 200: chosen of 20, 50, 100 and 200 on the 29 gate sequences,
    /// validated on five simulated sequences of other seeds (docs/verification.md, "200
    /// best-ranked, not 50").
    int layout_shortlist = 200;
    /// The decision threshold, tau (W <= tau, Röhling eq. 7) or t_d (sigma' < t_d, Magnusson
    /// II-E); empty: the method's default (pipeline::DefaultThreshold).
    std::optional<double> threshold;
    /// Register each candidate to its query and accept only loops that pass (docs/verification.md).
    /// Needs the scans (or their registration::PreparedScan), not descriptors alone. When on, the
    /// descriptor ranks candidates and the threshold prunes them only when set explicitly.
    bool verify = true;
    /// With verify: register the candidates in rank order and stop at the first accepted one
    /// (that the odometry gate keeps, when there is one); the rest get kNotNeeded, except those
    /// that may give the pose graph a further loop (optimise: app::PoseGraphLoopsWanted). About
    /// half the verification time on dense scans, a fifth on sparse keyframes, the same scans
    /// closed with poses as good (docs/BENCHMARK.md); a query's candidates are registered in
    /// rank order (online, as many at once as there are threads, decided one after another).
    /// Off: every candidate is registered (in parallel) and the loop is the accepted one that
    /// overlaps most.
    bool stop_at_first_loop = true;
    registration::VerificationConfig verification;  ///< YAML section `verification`

    /// core::PathAllows with min_path_m: false when both paths (metres) are known and lie not
    /// more than min_path_m apart; true when either is unknown (NaN).
    bool PathAllows(double path_i_m, double path_j_m) const {
        return core::PathAllows(min_path_m, path_i_m, path_j_m);
    }
    /// `threshold` when set, else the default of `method`.
    double ThresholdFor(const core::Method& method) const {
        return threshold ? *threshold : DefaultThreshold(method);
    }
    /// Throws ConfigError naming the first invalid field.
    void Validate() const;
    bool operator==(const DetectorConfig&) const = default;
};

/// What the detector says about one query scan.
struct LoopQuery {
    std::size_t query = 0;
    /// Up to top_k eligible scans, nearest by the descriptor first; where a LoopCheck orders
    /// them, in its order (the odometry's nearest view centres first,
    /// DetectorConfig::odometry_shortlist; else the most alike layouts first, layout_shortlist).
    std::vector<Neighbor> candidates;
    /// Distinctiveness of the best match: its distance over the distance of the best candidate
    /// that lies outside the gap around the best match (another place). Near 1: ambiguous;
    /// near 0: distinctive. NaN when there is no such second candidate, or the gap is in metres
    /// and the path unknown (localisation); 1 when both are 0.
    double second_ratio = std::numeric_limits<double>::quiet_NaN();
    /// Without verification: the best match passes the threshold (W <= tau, sigma' < t_d).
    /// With: some candidate passed verification (see loop()).
    bool accepted = false;
    /// Geometric verification of `candidates`, in their order; empty when not verified.
    std::vector<registration::Verification> verifications;

    bool has_match() const { return !candidates.empty(); }
    bool verified() const { return !verifications.empty(); }
    /// The index in `candidates` of the loop: of the candidates verification accepted, the one
    /// that overlaps best (Verification::score; the earlier on a tie), or without verification
    /// the best candidate when accepted; nullopt when there is no loop.
    std::optional<std::size_t> loop() const;
};

/// Knowledge besides the scans that judges a query's verified loops: the odometry
/// (app::OdometryLoopCheck). Empty: none.
struct LoopCheck {
    /// Rejects the accepted candidates of a query that the knowledge contradicts
    /// (RejectLoopsAgainstOdometry, reason kOdometryMismatch).
    std::function<void(LoopQuery&)> reject;
    /// The poses of a loop from scan `query` to scan `match` that `reject` keeps; an empty
    /// function where it cannot judge them (the odometry does not know both scans). The pair is
    /// verified with them (registration::Verify's `allowed`): the odometry stands in for the
    /// points that pin the position along a road. Empty: no pair is judged.
    std::function<registration::PoseAllowed(std::size_t query, std::size_t match)> allowed_poses;
    /// Without odometry: whether the scans' own motion will judge a loop from scan `query` to scan
    /// `match` (a chain of registered steps joins them: CheckAgainstMotion). The pair is then
    /// verified with acceptance.min_constraining_points_with_motion (VerifyQuery). Empty: no pair
    /// is judged so.
    std::function<bool(std::size_t query, std::size_t match)> motion_judges;

    /// Whether some loop from scan `query` to scan `match`, its sensors at most
    /// `max_loop_distance_m` apart (AcceptanceConfig), is one `reject` would keep; true where it
    /// cannot judge the pair. False lets the pair go unregistered: no registration could become
    /// its loop. Empty: every pair may close.
    std::function<bool(std::size_t query, std::size_t match, double max_loop_distance_m)> may_close;
    /// A cheap bound of may_close for the candidate search (positions and path only, a few
    /// nanoseconds): false only where may_close is false. It lets a query with few scans in reach
    /// skip the rest of a long run without ranking them. Empty: none.
    std::function<bool(std::size_t query, std::size_t match, double max_loop_distance_m)>
        in_reach_bound;
    /// How far apart the odometry puts the view centres (registration::PreparedScan::view_centre)
    /// of two scans, metres; NaN where it does not know both. A query's candidates are registered
    /// nearest first (DetectorConfig::odometry_shortlist). Empty: in rank order.
    std::function<double(std::size_t query, std::size_t match)> view_distance_m;
    /// How alike the layouts of two scans are (registration::LayoutSimilarity; NaN where either
    /// has none). Where view_distance_m does not order them, a query's candidates are the most
    /// alike of its shortlist (DetectorConfig::layout_shortlist), most alike first. Empty: in rank
    /// order.
    std::function<double(std::size_t query, std::size_t match)> layout_similarity;
    /// The yaws of a loop from scan `query` to scan `match` that `reject` may keep: the coarse
    /// search looks there only (registration::Verify's `yaws`). The whole circle where it cannot
    /// judge the pair. Empty: every yaw.
    std::function<registration::YawWindow(std::size_t query, std::size_t match)> yaw_window;
    /// Judges a sequence's verified queries together once all are verified: rejects the loops a
    /// longer chain of agreeing loops within `window_m` of path contradicts
    /// (RejectLoopsUnlikeTheirRevisit); returns how many. Empty: none.
    std::function<std::size_t(std::vector<LoopQuery>& queries, double window_m)> judge_revisits;

    explicit operator bool() const { return static_cast<bool>(reject); }
    void operator()(LoopQuery& query) const { reject(query); }
    registration::PoseAllowed AllowedPoses(std::size_t query, std::size_t match) const {
        return allowed_poses ? allowed_poses(query, match) : registration::PoseAllowed{};
    }
    bool MayClose(std::size_t query, std::size_t match, double max_loop_distance_m) const {
        return !may_close || may_close(query, match, max_loop_distance_m);
    }
    registration::YawWindow YawWindow(std::size_t query, std::size_t match) const {
        return yaw_window ? yaw_window(query, match) : registration::YawWindow{};
    }
    bool MotionJudges(std::size_t query, std::size_t match) const {
        return motion_judges && motion_judges(query, match);
    }
};

/// With DetectorConfig::stop_at_first_loop, once `query` has a loop: whether registering its
/// candidate `candidate` may still give a loop its user keeps, judged by the verdicts of the
/// candidates ranked before it (later ones may hold cached verdicts: ignore them), e.g. the pose
/// graph's further loops of a scan far apart in path (app::PoseGraphLoopsWanted). Empty: none
/// after the first.
using MoreLoopsWanted = std::function<bool(const LoopQuery& query, std::size_t candidate)>;

/// Whether the odometry contradicts a verified loop: given the loop's registered T_match_query,
/// the odometry's T_match_query and the path between the two scans (m); true rejects the loop.
/// app::OdometryGateOf makes the pose graph's gate (posegraph::GateAgainstOdometry) one.
struct OdometryGate {
    std::function<bool(const core::Transform& T_match_query_loop,
                       const core::Transform& T_match_query_odometry, double path_m)>
        rejects;
    /// The largest translation discrepancy (metres) `rejects` lets pass over `path_m` of path,
    /// whatever the rotation: a scan the odometry puts farther from the query than a loop's
    /// distance plus this cannot close a loop with it, which the candidate search tests before
    /// it ranks the scan (LoopCheck::in_reach_bound). Nondecreasing in path_m; NaN or empty:
    /// unknown (nothing is ruled out before it is ranked).
    std::function<double(double path_m)> translation_allowance_m;
    /// The largest rotation discrepancy (degrees) `rejects` lets pass over `path_m` of path: the
    /// coarse search of a pair looks for yaws within it of the odometry's (LoopCheck::
    /// yaw_window). NaN or empty: unknown (every yaw is searched).
    std::function<double(double path_m)> rotation_allowance_deg;

    explicit operator bool() const { return static_cast<bool>(rejects); }
    bool operator()(const core::Transform& T_match_query_loop,
                    const core::Transform& T_match_query_odometry, double path_m) const {
        return rejects(T_match_query_loop, T_match_query_odometry, path_m);
    }
};

/// Rejects (RejectReason::kOdometryMismatch) each accepted verification of `query` that `gate`
/// says the odometry contradicts, and chooses the query's loop again among the rest.
/// `T_odom_sensor_of(j)`: scan j's pose by the odometry; `path_m_of(j)`: its cumulative path. A
/// loop to or from a scan whose pose or path is not finite is kept (the odometry cannot judge
/// it). Returns how many it rejected.
std::size_t RejectLoopsAgainstOdometry(
    LoopQuery& query, const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of, const OdometryGate& gate);

/// Rejects (RejectReason::kUnlikeFits) each accepted verification of `query` that more of the
/// fits of the candidates ranked before it contradict than agree with it (its own counts for it,
/// a tie rejects). A fit votes when `gate` allows its pose: accepted or rejected only as too far
/// one vote, rejected only as ambiguous half (either of its poses may be the place). Its pose
/// and the loop's put the two matches relative to each other, which `gate` judges against the
/// odometry between the matches. A verification found before the candidates ranked before it
/// were decided (reason kNone, not accepted) is judged once they are. Does not choose the loop
/// again.
void RejectLoopsUnlikeEarlierFits(
    LoopQuery& query, const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of, const OdometryGate& gate);

/// Rejects (RejectReason::kUnlikeRevisit) the accepted verifications of `queries` that a longer
/// chain of agreeing loops of their revisit contradicts. Two loops are neighbours when their
/// queries lie within `window_m` of path of each other and their matches too; the odometry
/// carries one over to the other (T_match_query ≈ T_match_other · T_other_query' ·
/// T_query'_query, both links by the odometry) and `gate` judges the two over the path of the
/// links. Neighbours that agree join one chain; of two chains with a neighbour pair that
/// disagrees, the one with fewer queries is rejected, both when as many (a pair that disagrees
/// within one chain decides nothing). Every loop is judged as the loops were before, so the
/// order does not matter; the loops to or from a scan the odometry does not know are neither
/// judged nor judge. Then each query's loop is chosen again among the rest. Returns how many it
/// rejected.
std::size_t RejectLoopsUnlikeTheirRevisit(
    std::vector<LoopQuery>& queries,
    const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of, const OdometryGate& gate, double window_m);

/// Whether `gate` lets some loop pose from scan `query` to scan `match` pass, its sensors at most
/// `max_loop_distance_m` apart: it tries the one nearest to the odometry's relative pose (its
/// rotation, its translation shortened to that distance), which a gate that judges the size of
/// the translation and rotation discrepancy (posegraph::GateAgainstOdometry) passes if any such
/// pose passes. True where the odometry does not know both scans' poses and path (finite).
bool OdometryAllowsALoop(std::size_t query, std::size_t match, double max_loop_distance_m,
                         const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
                         const std::function<double(std::size_t)>& path_m_of,
                         const OdometryGate& gate);

/// The poses of a loop from scan `query` to scan `match` that `gate` lets pass against the
/// odometry (as RejectLoopsAgainstOdometry judges them); an empty function when the odometry
/// does not know both scans' poses and path (finite).
registration::PoseAllowed OdometryAllowedPoses(
    std::size_t query, std::size_t match,
    const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of, const OdometryGate& gate);

/// The yaws of a loop from scan `query` to scan `match` that `gate` may let pass: within its
/// rotation allowance of the odometry's relative yaw. Whole where the odometry does not know both
/// scans' poses and path, or the gate has no allowance.
registration::YawWindow OdometryYawWindow(
    std::size_t query, std::size_t match,
    const std::function<core::Transform(std::size_t)>& T_odom_sensor_of,
    const std::function<double(std::size_t)>& path_m_of, const OdometryGate& gate);

/// The odometry as a LoopCheck: RejectLoopsAgainstOdometry on each verified query, and for each
/// pair the poses OdometryAllowedPoses lets pass and the yaws OdometryYawWindow holds. Adds the
/// rejections to `rejected` when given (thread-safe). With `view_centre_of(j)` (scan j's
/// PreparedScan::view_centre, sensor frame), also the distance of two scans' view centres in the
/// odometry's frame (view_distance_m). The functions are copied; what they refer to must outlive
/// the check.
LoopCheck CheckAgainstOdometry(std::function<core::Transform(std::size_t)> T_odom_sensor_of,
                               std::function<double(std::size_t)> path_m_of, OdometryGate gate,
                               std::atomic<std::size_t>* rejected = nullptr,
                               std::function<Eigen::Vector3d(std::size_t)> view_centre_of = {});

/// The layouts of prepared scans (registration::CompactPreparedScan::layout) as a LoopCheck's
/// layout_similarity and, where coarse.layout_yaw_window_deg is under 180, its yaw_window (the
/// layouts' yaw and half a turn from it, registration::LayoutYaw; every yaw for a pair without
/// both): scan i's is scans[i]'s, and with `query` the scan after them (index scans.size(), a
/// query not stored yet, as the detector searches it) is `query`'s. Refers to `scans` and
/// `query`.
LoopCheck LayoutOrderOf(const std::vector<registration::CompactPreparedScan>& scans,
                        const registration::CoarseConfig& coarse,
                        const registration::CompactPreparedScan* query = nullptr);

/// The k nearest of the scans 0..count-1 for which `eligible(j)` holds, by (distance, index),
/// with `distance_of(j)` (called for eligible scans only; +inf and NaN are never candidates):
/// the brute-force search both detectors share. O(k) memory (a bounded heap).
std::vector<Neighbor> NearestCandidates(std::size_t count, std::size_t k,
                                        const std::function<double(std::size_t)>& distance_of,
                                        const std::function<bool(std::size_t)>& eligible);

/// Online loop detection: scans arrive one at a time; each is compared with the stored scans
/// older than the minimum gap, then stored. Candidates come from the method's index where it has
/// one (histograms: the exact HistogramIndex; scancontext with ring_key_candidates > 0: the
/// approximate ring-key search), else from comparing every eligible scan (NDT).
/// With DetectorConfig::verify, a scan given as a point cloud is also kept reduced for
/// registration (registration::PreparedScan: a few thousand voxel centroids with normals, about
/// 0.1 MB instead of a raw HDL-64E scan's 2 MB; prepared_bytes()) and its candidates are
/// verified against the stored reduced scans; a scan given as a descriptor alone is neither
/// verified nor verifiable as a candidate (kTooFewPoints).
/// Given each scan's pose by the odometry (Process's T_odom_sensor), it also measures the gap
/// in metres of path, and with an odometry gate (SetOdometryGate) rejects the loops the
/// odometry contradicts, as `detect --odometry` does (docs/verification.md, "The odometry's
/// word"). Scans given with and without a pose do not mix; a loaded map's scans have none, and
/// with a gap in metres they are always candidates (another session: no path separates them).
/// Process is not thread-safe; Query may run concurrently.
/// Neither copyable nor movable: the index refers to the detector's own database.
class LoopDetector {
public:
    /// Validates the configs.
    LoopDetector(const core::DescriptorConfig& descriptor, const DetectorConfig& detector);
    /// Continues from a loaded database (e.g. a map): every stored scan becomes searchable.
    /// `scans`: the stored scans prepared for verification (by database index, with
    /// detector.verification.reduction), or empty when the map has none.
    LoopDetector(DescriptorDatabase database, const DetectorConfig& detector,
                 std::vector<registration::PreparedScan> scans = {});
    LoopDetector(const LoopDetector&) = delete;
    LoopDetector& operator=(const LoopDetector&) = delete;
    ~LoopDetector();

    /// Describes `scan`, finds its candidates among the stored scans (and verifies them when
    /// verify is on, then applies the odometry gate; with the gate, a scan the odometry puts out
    /// of a loop's reach is then no candidate, and the candidates are the nearest views of the
    /// odometry_shortlist best-ranked ones), then stores it. `T_odom_sensor`: the
    /// scan's pose by the odometry, given for every scan or for none. ConfigError for a gap in
    /// metres without it, for a pose on some scans only, for a pose that is not finite, and for
    /// a time that is not finite or earlier than the scan before's in this session.
    LoopQuery Process(const core::PointCloud& scan, double time_s,
                      const std::optional<core::Transform>& T_odom_sensor = std::nullopt);
    /// The same for a scan described (and, for verification, prepared) by the caller; an empty
    /// `scan` is not verified.
    LoopQuery Process(const core::Descriptor& descriptor, double time_s,
                      registration::PreparedScan scan = {},
                      const std::optional<core::Transform>& T_odom_sensor = std::nullopt);
    /// The odometry gate applied to verified loops between scans given with poses (none by
    /// default; an empty function removes it).
    void SetOdometryGate(OdometryGate gate) { odometry_gate_ = std::move(gate); }
    /// Localisation against the stored scans: every stored scan is eligible and the query is not
    /// stored. Verified when verify is on and `scan` (the query, prepared) is not empty.
    LoopQuery Query(const core::Descriptor& descriptor,
                    const registration::PreparedScan& scan = {}) const;
    /// The same for a prepared query (e.g. DescriptorDatabase::PrepareStored of another
    /// database with the same configuration); `query_index` only labels the result.
    LoopQuery Query(const PreparedQuery& query, std::size_t query_index,
                    const registration::PreparedScan& scan = {}) const;
    /// The same for a query scan kept compact.
    LoopQuery Query(const PreparedQuery& query, std::size_t query_index,
                    const registration::CompactPreparedScan& scan) const;

    const DescriptorDatabase& database() const { return database_; }
    const DetectorConfig& detector_config() const { return detector_; }
    /// The decision threshold applied (detector_config().ThresholdFor the database's method).
    double threshold() const { return threshold_; }
    /// The stored scans prepared for verification (by database index; empty ones were given as
    /// descriptors), and their heap bytes in all.
    const std::vector<registration::CompactPreparedScan>& prepared_scans() const { return scans_; }
    std::size_t prepared_bytes() const;

private:
    LoopQuery Search(const PreparedQuery& query, std::size_t query_index,
                     const std::function<bool(std::size_t)>& eligible,
                     const std::vector<double>& path_m = {}, const LoopCheck& check = {}) const;
    void Verify(LoopQuery& result, const registration::CompactPreparedScan& scan,
                const LoopCheck& check = {}) const;
    // The next scan's cumulative path (m) from its odometry pose; nullopt without odometry.
    // Throws ConfigError when the pose is missing where it is needed, or not finite.
    std::optional<double> PathOf(const std::optional<core::Transform>& T_odom_sensor) const;

    DescriptorDatabase database_;
    DetectorConfig detector_;
    double threshold_;
    std::unique_ptr<NeighborIndex> index_;  // nullptr: compare every eligible scan
    // By database index, for verification; compact (about 36 kB a scan instead of 214 kB expanded).
    std::vector<registration::CompactPreparedScan> scans_;
    mutable ExpandedScans expanded_;  // the candidates verified lately (thread-safe)
    // Without odometry, what each stored scan shows with its neighbour (thread-safe).
    std::unique_ptr<NeighbourOverlaps> neighbours_;
    // The scans loaded from a map come first; this session's scans start here.
    std::size_t session_start_ = 0;
    // With odometry: per scan of this session, its pose T_odom_sensor and cumulative path (m);
    // empty without.
    std::vector<core::Transform> odometry_;
    std::vector<double> path_m_;
    OdometryGate odometry_gate_;
};

/// Localisation of a whole sequence against a map: LoopDetector::Query for every scan of
/// `queries` (described with the map's configuration, which is checked), in parallel. Result i
/// belongs to query scan i; a scan that could not be read has no candidates. `query_scans`
/// (query scan i prepared and kept compact, or empty) are verified against the map's prepared
/// scans.
std::vector<LoopQuery> LocaliseSequence(
    const LoopDetector& map, const DescriptorDatabase& queries,
    Execution execution = Execution::kParallel,
    const std::vector<registration::CompactPreparedScan>& query_scans = {});

/// Offline detection from a full similarity matrix: for every scan i, the candidates among the
/// scans j < i outside the gap, exactly as LoopDetector::Process would give them online.
/// `path_m`: per scan, the cumulative path length (core::CumulativePathM), needed (one per scan,
/// else ConfigError) only for a gap in metres. A scan `check` says cannot close a loop with the
/// query (LoopCheck::MayClose within the verification's max_loop_distance_m: the odometry puts it
/// out of reach) is no candidate, so that the top k are k scans verification can use; as online.
std::vector<LoopQuery> DetectFromMatrix(const SimilarityMatrix& matrix,
                                        const std::vector<double>& times_s,
                                        const DetectorConfig& detector, const core::Method& method,
                                        const std::vector<double>& path_m = {},
                                        const LoopCheck& check = {});

/// Offline detection without the similarity matrix: exactly DetectFromMatrix on
/// ComputeSimilarityMatrix(database) (distances rounded to float as the matrix holds them) when
/// the method's index is exact, a query at a time, in parallel unless told otherwise (an
/// approximate index, scancontext's ring-key search, gives its own candidates). Candidates come
/// from the method's index where it has one (histograms: a few more than asked, re-ranked by the
/// float distance; when a float tie at the last place could hide another scan, from comparing them
/// all), else from comparing every eligible scan (NDT). Memory: the results, the index and one row
/// of n floats per thread, instead of the matrix's 2 n^2 bytes. `path_m` and `check` as
/// DetectFromMatrix's.
std::vector<LoopQuery> DetectStreaming(const DescriptorDatabase& database,
                                       const DetectorConfig& detector,
                                       Execution execution = Execution::kParallel,
                                       const std::vector<double>& path_m = {},
                                       const LoopCheck& check = {});

/// DetectStreaming a query at a time: Detect(i) gives scan i's LoopQuery as DetectStreaming
/// gives it (and LoopDetector::Process online), from the method's index over the database's
/// valid scans (built once) or by comparing the earlier scans. `bench` times it as the online
/// step's candidate search. Detect is thread-safe. Refers to `database` (and keeps copies of
/// the rest; what `check`'s functions refer to must outlive it); ConfigError as DetectStreaming.
class StreamingDetection {
public:
    StreamingDetection(const DescriptorDatabase& database, const DetectorConfig& detector,
                       const std::vector<double>& path_m = {}, const LoopCheck& check = {});
    ~StreamingDetection();
    StreamingDetection(const StreamingDetection&) = delete;
    StreamingDetection& operator=(const StreamingDetection&) = delete;

    LoopQuery Detect(std::size_t query) const;

private:
    const DescriptorDatabase& database_;
    DetectorConfig detector_;
    std::vector<double> path_m_;
    LoopCheck check_;
    double threshold_;
    std::vector<double> along_;  ///< the scans' positions in the gap's unit (MinGap::Along)
    std::unique_ptr<NeighborIndex> index_;
};

}  // namespace lidarloop::pipeline

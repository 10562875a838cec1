#pragma once

#include <atomic>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarloop/app/progress.hpp"
#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/pipeline/candidate_verification.hpp"
#include "lidarloop/pipeline/neighbour_overlaps.hpp"
#include "lidarloop/posegraph/pose_graph_config.hpp"
#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/prepared_scan.hpp"
#include "lidarloop/registration/verification.hpp"

namespace lidarloop::app {

/// Every scan of a sequence prepared for verification, filled while the scans are described.
struct PreparedScans {
    /// By scan index, kept compact for the whole run; empty for skipped scans.
    std::vector<registration::CompactPreparedScan> scans;
    std::vector<double> prepare_seconds;      ///< per scan, wall time
    std::vector<double> prepare_cpu_seconds;  ///< per scan, thread CPU time
    std::vector<char> readable;               ///< per scan, 1 when it was read

    /// Where each scan alone registered to the one before placed the submaps (no odometry:
    /// PrepareSubmapsFromNeighbours), those registrations, kept for the neighbour and motion rules.
    std::shared_ptr<pipeline::NeighbourOverlaps> neighbours;
    /// Then the pairs whose submaps are apart (pipeline::SubmapsApart): the candidate search's
    /// check where no odometry judges. Empty otherwise.
    pipeline::LoopCheck submaps_apart;

    explicit PreparedScans(std::size_t count)
        : scans(count),
          prepare_seconds(count, 0.0),
          prepare_cpu_seconds(count, 0.0),
          readable(count, 0) {}

    /// A DescribeRun::with_cloud callback that prepares scan i into scans[i] (thread-safe for
    /// distinct scans). The callback refers to this object and `reduction`.
    std::function<void(std::size_t, const core::PointCloud&)> Collector(
        const registration::ScanReductionConfig& reduction);
    /// One that only notes which scans were read: with submaps (PrepareSubmaps) a scan alone is
    /// never verified, so it is not prepared alone first.
    std::function<void(std::size_t, const core::PointCloud&)> ReadMarker();
    /// The callback of a run verifying with `reduction`: Collector, or ReadMarker with submaps
    /// (submap_path_m > 0; PrepareSubmaps follows once every scan was read).
    std::function<void(std::size_t, const core::PointCloud&)> CollectorFor(
        const registration::ScanReductionConfig& reduction);
    /// Heap bytes of the prepared scans, per scan (skipped scans excluded).
    std::vector<double> BytesPerScan() const;
};

/// Receives scan i's submap and the seconds it took (its share of the block's reads included),
/// from worker threads.
using SubmapSink = std::function<void(std::size_t, registration::PreparedScan, double)>;

/// Prepares scan i as its submap (registration::PrepareSubmap with `reduction`'s window, `poses`
/// one per scan) for every i with `wanted(i)`, reading each scan once (`load`, as
/// PrepareSubmap's) where reading every submap's members would read each scan about twice the
/// window's member count: the centres go in blocks of consecutive scans, a block's members are
/// read in parallel and kept while the next block needs them, and its submaps are prepared in
/// parallel. Memory: the scans of one block and its two windows.
void PrepareSubmapsInOrder(const std::vector<core::StampedPose>& poses,
                           const registration::ScanReductionConfig& reduction,
                           const std::function<core::PointCloud(std::size_t)>& load,
                           const std::function<bool(std::size_t)>& wanted, const SubmapSink& take);

/// Prepares every scan again as its submap (registration::PrepareSubmap with `reduction`'s
/// window) from the scans of `dataset` placed by `poses` (one per scan), in parallel, telling
/// `progress` as stage "submaps". Scans skipped while describing (not `readable`) stay empty and
/// join no submap. The pair times of verification then include the larger scans.
void PrepareSubmaps(const io::Dataset& dataset, const std::vector<core::StampedPose>& poses,
                    const registration::ScanReductionConfig& reduction, PreparedScans& prepared,
                    const Progress& progress);

/// Where no odometry is given (offline, every scan read and prepared alone into `prepared`):
/// registers each scan to the one before (pipeline::PosesFromNeighbours, kept in
/// prepared.neighbours), then prepares every scan again as its submap placed by those
/// registrations (PrepareSubmaps), telling `progress` as stages "neighbours" and "submaps".
void PrepareSubmapsFromNeighbours(const io::Dataset& dataset,
                                  const registration::VerificationConfig& verification,
                                  PreparedScans& prepared, const Progress& progress);

/// Replaces each prepared scan by its submap where `verification` asks for submaps
/// (submap_path_m > 0): placed by `odometry` (PrepareSubmaps), or without it by the scans'
/// registrations to their neighbours (PrepareSubmapsFromNeighbours).
void PrepareSubmapsIfAsked(const io::Dataset& dataset,
                           const std::vector<core::StampedPose>& odometry,
                           const registration::VerificationConfig& verification,
                           PreparedScans& prepared, const Progress& progress);

/// Whether a run without `odometry` places submaps by the scans' registrations to their
/// neighbours: none is given and the scans follow one another, not frames picked from a longer
/// drive (whose poses name their frames: core::KnowsDrivePath of the dataset's poses).
bool NeighboursPlaceSubmaps(const io::Dataset& dataset,
                            const std::vector<core::StampedPose>& odometry);

/// Whether scans are prepared as submaps: the config asks for them and `poses` (the odometry,
/// never a dataset's ground truth) has one per scan, or, with `neighbours_place`, none is given
/// (PrepareSubmapsFromNeighbours). `note` tells why not when asked for, or that the neighbours
/// place them.
bool SubmapsApply(const registration::ScanReductionConfig& reduction,
                  const std::vector<core::StampedPose>& poses, std::size_t scans, std::string& note,
                  bool neighbours_place = false);

/// `config` as a run on `dataset` applies it: submaps only where SubmapsApply and, with
/// `alone_when_dense`, not where ScansFillTheStructureCap (the scans are verified alone: docs/
/// verification.md, "Dense scans need no submaps"); else submap_path_m 0, with the reason in
/// `notes`, so that config.yaml and database.scans say what was done.
io::RunConfig WithSubmapsWhereTheyApply(const io::RunConfig& config, const io::Dataset& dataset,
                                        const std::vector<core::StampedPose>& poses,
                                        std::vector<std::string>& notes, bool neighbours_place,
                                        bool alone_when_dense);

/// Whether the typical scan of `dataset` fills the reduction's structure cap alone
/// (max_structure_points): the median over up to 15 scans spread evenly along the sequence,
/// each prepared alone; scans that cannot be read are left out (false when none can). Such
/// scans gain no density from their neighbours, only their cost.
bool ScansFillTheStructureCap(const io::Dataset& dataset,
                              const registration::ScanReductionConfig& reduction);

/// pipeline::VerifyQueries over `queries`, telling `progress` as stage "verifying"; `check`
/// (e.g. OdometryLoopCheck) runs on each verified query.
pipeline::VerificationTimes VerifyAll(std::vector<pipeline::LoopQuery>& queries,
                                      const PreparedScans& prepared,
                                      const pipeline::DetectorConfig& detector,
                                      const core::Method& method, const Progress& progress,
                                      pipeline::VerificationCache* cache = nullptr,
                                      const pipeline::LoopCheck& check = {},
                                      const pipeline::MoreLoopsWanted& more = {});

/// The pose graph's odometry gate (posegraph::GateAgainstOdometry with `config`'s robust and
/// information sections) as the detectors take it: `detect --odometry`, and the online
/// LoopDetector (SetOdometryGate) when it is given the odometry.
pipeline::OdometryGate OdometryGateOf(const posegraph::PoseGraphConfig& config);

/// Rejects (RejectReason::kOdometryMismatch) every accepted candidate whose registered pose the
/// odometry contradicts beyond its drift (posegraph::GateAgainstOdometry with `posegraph`'s gate)
/// and chooses each query's loop again among the rest: a place that repeats itself (a street
/// with a period of 45 m) registers well at the wrong place, and the odometry knows better over
/// a short path. `odometry`: T_world_sensor of each scan; `path_m`: its cumulative path, one per
/// scan. Returns how many it rejected. A loop to or from a scan whose pose or path is not finite
/// is kept (the odometry cannot judge it). Throws core::ConfigError when a query or candidate
/// has no odometry.
std::size_t RejectLoopsAgainstOdometry(std::vector<pipeline::LoopQuery>& queries,
                                       const std::vector<core::StampedPose>& odometry,
                                       const std::vector<double>& path_m,
                                       const posegraph::PoseGraphConfig& config);

/// RejectLoopsAgainstOdometry for one query at a time, as verification runs it (VerifyAll):
/// with detection.stop_at_first_loop a loop the odometry rejects lets the next candidate be
/// registered. Adds the rejections to `rejected` when given (thread-safe). With `prepared`, a
/// query's candidates are ordered by the odometry's distance of their view centres
/// (pipeline::LoopCheck::view_distance_m, detection.odometry_shortlist). The vectors are
/// referenced, not copied: they must outlive the check.
pipeline::LoopCheck OdometryLoopCheck(const std::vector<core::StampedPose>& odometry,
                                      const std::vector<double>& path_m,
                                      const posegraph::PoseGraphConfig& config,
                                      std::atomic<std::size_t>* rejected = nullptr,
                                      const PreparedScans* prepared = nullptr);

/// The check of a run verifying without odometry: the submaps' (PreparedScans::submaps_apart),
/// a query's candidates ordered by how alike their layouts are to its own
/// (pipeline::LoopCheck::layout_similarity, detection.layout_shortlist), and the yaws the
/// layouts suggest (coarse.layout_yaw_window_deg). Refers to `prepared`.
pipeline::LoopCheck ScansOwnCheck(const PreparedScans& prepared,
                                  const registration::CoarseConfig& coarse);

/// The figures of a verification run for timings.json: per scan preparation (ms) and memory
/// (bytes), per query coarse images (ms), per candidate pair (ms), counts.
nlohmann::json VerificationTimingsJson(const PreparedScans& prepared,
                                       const pipeline::VerificationTimes& times);

/// What `lidarloop verify` computed for one pair of scan files.
struct PairVerification {
    registration::Verification verdict;
    std::size_t query_points = 0;  ///< points read from each file
    std::size_t match_points = 0;
    double prepare_ms = 0.0;  ///< preparing both scans
    double verify_ms = 0.0;   ///< coarse search, ICP and acceptance
};

/// Prepares two scans (sensor frames, metres) and verifies the first as the query against the
/// second (registration::Verify), timing both steps: what `lidarloop verify` and the Python
/// lidarloop.verify_pair compute. Validates `config` (core::ConfigError).
PairVerification VerifyClouds(const core::PointCloud& query, const core::PointCloud& match,
                              const registration::VerificationConfig& config);

/// Reads two scan files (io::ReadScan; errors name the file) and verifies the first as the
/// query against the second (VerifyClouds). Validates `config` (core::ConfigError).
PairVerification VerifyScanFiles(const std::filesystem::path& query_file,
                                 const std::filesystem::path& match_file,
                                 const registration::VerificationConfig& config);

/// One verdict as JSON: accepted, reason, T_match_query (4x4, row-major, nested lists: maps
/// query points into the match frame, metres), overlap (the smaller fraction), rmse_m, and the
/// details (both overlap fractions, overlapping points, the degeneracy ratio, coarse score).
nlohmann::json VerificationJson(const registration::Verification& verdict);

}  // namespace lidarloop::app

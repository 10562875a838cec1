#pragma once

#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/core/kd_tree.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::eval {

/// "No such scan" in per-scan results (no partner outside the gap, no match).
inline constexpr std::size_t kNoScan = std::numeric_limits<std::size_t>::max();

/// When two scans of a sequence show the same place (a "loop" pair, a positive).
///
/// Röhling et al. 2015 (IV-B): two scans are the same place when their ground-truth positions
/// are less than d = 10 m apart; every pair of scans is evaluated. Magnusson et al. 2009 (II-E,
/// III-B): a scan overlaps when some scan outside the minimum loop size S is closer than t_r
/// (10 m Hannover2, 5 m Kvarntorp); for the 180° scanner of Kvarntorp only scans whose
/// orientation differs by less than 20° count.
struct GroundTruthConfig {
    /// d (Röhling) or t_r (Magnusson): a pair is positive when the 3-D distance between the
    /// sensor positions is strictly below this, metres, > 0.
    double distance_m = 10.0;
    /// Largest heading difference of a positive pair, degrees in [0, 180]; a pair is positive
    /// only when the difference is strictly below it. 0 disables the rule (omnidirectional
    /// scanners); Magnusson uses 20 for Kvarntorp. See HeadingDifferenceDeg for the angle.
    double max_heading_deg = 0.0;
    /// Pairs closer than this in the sequence are never evaluated (neither positive nor
    /// negative). Röhling evaluates every pair (0 scans, the default); Magnusson uses S = 30.
    core::MinGap min_gap{0.0, core::MinGap::Unit::kScans};
    /// And pairs whose path between them (along the poses, core::CumulativePathM) is not longer
    /// than this, metres >= 0, are not evaluated either: revisits as SLAM users count them, the
    /// drift a loop removes. 0 (the default) disables the rule.
    double min_path_m = 0.0;

    /// Throws core::ConfigError naming the first invalid field (prefix "ground_truth.").
    void Validate() const;
    /// The rule in one English sentence, for reports.
    std::string Describe() const;
};

/// Angle between the headings of two sensor poses, degrees in [0, 180]: the angle between the
/// sensors' forward (x) axes after projecting them on the world ground plane (world z up).
/// Chosen over the full rotation angle because Magnusson's rule is about where a ground robot's
/// 180° scanner points; roll and pitch from uneven ground do not change the view much. A sensor
/// looking straight up or down (within ~1e-6 rad) has no heading and is 0° from every other
/// heading. Thread-safe.
double HeadingDifferenceDeg(const core::Transform& T_world_a, const core::Transform& T_world_b);

/// One positive pair: scans i < j, and the distance between their sensor positions.
struct LoopPair {
    std::size_t i = 0;
    std::size_t j = 0;
    double distance_m = 0.0;
};

/// The ground truth of one sequence under one GroundTruthConfig. The positive pairs are not
/// stored: they are a pure function of the poses, so IsLoop applies the rule to two scans (O(1))
/// and ForEachLoop enumerates them through a k-d tree. Memory is O(n) whatever the number of
/// positives (a list of them cost 40 bytes a pair: 92 M pairs at 100,000 simulated scans). Copies
/// share the tree. Build with BuildGroundTruth.
struct GroundTruth {
    GroundTruthConfig config;
    std::vector<double> times_s;               ///< per scan, the pose times (for a gap in seconds)
    std::vector<double> path_m;                ///< per scan, core::CumulativePathM of the poses
    std::vector<Eigen::Vector3d> positions_m;  ///< per scan, the sensor position, world frame
    /// Per scan, the sensor's forward axis projected on the world ground plane (not
    /// normalised); empty when the heading rule is off.
    std::vector<Eigen::Vector2d> ground_headings;
    /// Per scan, the nearest scan outside the gap that also passes the heading rule (Magnusson
    /// table I: Ŝ), or kNoScan when there is none.
    std::vector<std::size_t> nearest;
    /// Per scan, the distance to `nearest`, metres (+inf when there is none).
    std::vector<double> nearest_distance_m;
    /// Per scan, its smallest positive partner (earlier or later), or kNoScan when it has none.
    std::vector<std::size_t> first_partner;
    std::size_t loop_count = 0;                 ///< number of positive pairs i < j
    std::shared_ptr<const core::KdTree3> tree;  ///< over positions_m, for ForEachLoop

    std::size_t size() const { return times_s.size(); }
    /// True when scans i and j are distinct and outside the minimum gap (the rule a detector's
    /// candidates obey).
    bool OutsideGap(std::size_t i, std::size_t j) const {
        const std::vector<double>& along = config.min_gap.Along(times_s, path_m);
        return i != j && config.min_gap.Allows(i, j, along[i], along[j]);
    }
    /// True when scans i and j are far enough apart in the sequence to be evaluated: outside
    /// the gap, and more than min_path_m of path apart when that rule is on.
    bool Comparable(std::size_t i, std::size_t j) const {
        // path_m is read only with the rule on (a hand-built truth may have no path).
        return OutsideGap(i, j) && (config.min_path_m <= 0.0 ||
                                    core::PathAllows(config.min_path_m, path_m[i], path_m[j]));
    }
    /// The rules besides the distance: Comparable, and headings closer than max_heading_deg
    /// when the heading rule is on.
    bool SamePlaceRules(std::size_t i, std::size_t j) const;
    /// True when (i, j), in either order, is a positive pair: the rule itself, decided by the
    /// same expressions as the k-d tree's radius search, so it agrees with ForEachLoop exactly
    /// (also at a distance of exactly distance_m, which is negative). O(1), thread-safe.
    bool IsLoop(std::size_t i, std::size_t j) const;
    /// Calls each(pair) for every positive pair, i < j, in ascending (i, j) order. O(n log n + P)
    /// time, O(largest neighbourhood) memory.
    void ForEachLoop(const std::function<void(const LoopPair&)>& each) const;
    /// All positive pairs, sorted by (i, j): O(P) memory, for tests and small sequences.
    std::vector<LoopPair> Loops() const;
    /// True when scan i has at least one positive partner (Magnusson: an "overlapping" scan;
    /// nearest_distance_m[i] < distance_m, up to rounding exactly at the boundary).
    bool Overlapping(std::size_t i) const { return first_partner[i] != kNoScan; }
    /// Number of overlapping scans.
    std::size_t OverlappingCount() const;
    /// Number of pairs i < j that are Comparable (positives + negatives of the pair-wise
    /// evaluation).
    std::size_t ComparablePairCount() const;
    /// config.Describe() plus the counts, for reports.
    std::string Describe() const;
};

/// Builds the ground truth from the scans' poses with a k-d tree radius search (not all pairs):
/// O(n log n + P) time for P positive pairs, plus the nearest-partner search; O(n) memory. Throws
/// core::ConfigError for an invalid config and when a pose or time is not finite.
/// Thread-safe.
GroundTruth BuildGroundTruth(const std::vector<core::StampedPose>& poses,
                             const GroundTruthConfig& config);

}  // namespace lidarloop::eval

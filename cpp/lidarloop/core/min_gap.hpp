#pragma once

#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::core {

/// Minimum loop size S (Magnusson et al. 2009, II-E): scans this close in the sequence are never
/// loop candidates of each other, since consecutive scans trivially look alike. Counted in scans
/// (the paper: "each scan S_i is compared to all other scans, except for S_{i-S}, ..., S_{i+S}"),
/// in seconds of recording time, or in metres of path travelled between the two scans (the drift
/// a loop can remove; on a slow platform 30 scans may be only a few metres).
struct MinGap {
    enum class Unit { kScans, kSeconds, kMetres };

    double value = 30.0;  ///< S; the paper uses 30 scans
    Unit unit = Unit::kScans;

    /// True when scans i and j are far enough apart to be compared. `along_i`, `along_j`: where
    /// the scans lie along the sequence in the gap's unit, ignored for scans: the recording time
    /// (s) for seconds, the cumulative path length (m, CumulativePathM) for metres.
    bool Allows(std::size_t i, std::size_t j, double along_i, double along_j) const {
        if (unit == Unit::kScans) {
            const double apart = i > j ? static_cast<double>(i - j) : static_cast<double>(j - i);
            return apart > value;
        }
        return (along_i > along_j ? along_i - along_j : along_j - along_i) > value;
    }
    /// The per-scan positions Allows takes in this unit: `path_m` for metres, else `times_s`.
    const std::vector<double>& Along(const std::vector<double>& times_s,
                                     const std::vector<double>& path_m) const {
        return unit == Unit::kMetres ? path_m : times_s;
    }

    /// Throws ConfigError naming `field` when value is negative or not finite.
    void Validate(const std::string& field) const;
    bool operator==(const MinGap&) const = default;
};

/// The path rule beside the gap (detection.min_path_m): true when two scans lie more than
/// `min_path_m` of path apart (`path_i_m`, `path_j_m`: CumulativePathM), when `min_path_m` is 0
/// (no rule), or when either path is unknown (NaN). Detection and evaluation share it.
inline bool PathAllows(double min_path_m, double path_i_m, double path_j_m) {
    return min_path_m <= 0.0 || !(std::abs(path_i_m - path_j_m) <= min_path_m);
}

std::string ToString(MinGap::Unit unit);
/// Parses "scans" / "seconds" / "metres"; throws ConfigError listing the valid names.
MinGap::Unit ParseMinGapUnit(std::string_view name);

/// True when every pose knows the path to it along a longer drive (StampedPose::path_m: some
/// frames of a KITTI sequence); false for none.
bool KnowsDrivePath(const std::vector<StampedPose>& poses);

/// Per scan, the length of the path travelled from the first scan, metres: the sum of the
/// straight-line steps between consecutive sensor positions (T_world_sensor), or, when every
/// pose knows its path (StampedPose::path_m: frames of a longer trajectory), that path. The path
/// between scans i and j is |path[i] - path[j]|. Empty for no poses. Throws Error naming the pose
/// when a position is not finite.
std::vector<double> CumulativePathM(const std::vector<StampedPose>& poses);

/// Throws ConfigError naming `what` and the scan when a path position (metres per scan, as
/// CumulativePathM gives) is not finite or lies before the one of the scan before it: a path
/// given from outside (Python's path_m, a pose graph's) must be one a drive can have.
void CheckPathM(std::span<const double> path_m, const std::string& what);

}  // namespace lidarloop::core

#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/registration/prepared_scan.hpp"
#include "lidarloop/registration/verification_config.hpp"

namespace lidarloop::registration {

/// Which neighbours of a scan join its submap: the scans within `path_m` metres of path of it,
/// at most `max_scans` on each side (the nearest in sequence order), and with `past_only` none
/// after it (online, only the past exists).
struct SubmapWindow {
    double path_m = 0.0;
    int max_scans = 0;
    bool past_only = false;
};

/// Per scan, the path travelled from the first scan along `poses` (T_world_sensor), metres, as
/// core::CumulativePathM (the drive's path when every pose knows it: StampedPose::path_m) but
/// tolerant: a scan whose pose is not finite gets NaN (it joins no submap) and the path
/// continues from the last finite pose.
std::vector<double> SubmapPathM(const std::vector<core::StampedPose>& poses);

/// The scans of `centre`'s submap in sequence order, `centre` included: those whose path
/// position (`path_m`, SubmapPathM) lies within window.path_m of centre's. Only `centre` when
/// its own position is NaN (no pose: nothing can be placed in its frame) or out of range.
std::vector<std::size_t> SubmapMembers(const std::vector<double>& path_m, std::size_t centre,
                                       const SubmapWindow& window);

/// The points of `scans` in the frame of `T_world_centre`: each scan's usable points (finite,
/// within config's range limits of its own sensor, so that no scan contributes its own vehicle)
/// moved by T_centre_scan = T_world_centre^-1 T_world_scan. A scan whose pose is not finite
/// contributes nothing. `T_world_scans[i]` belongs to `scans[i]`.
core::PointCloud MergeIntoFrame(const std::vector<core::PointCloud>& scans,
                                const std::vector<core::Transform>& T_world_scans,
                                const core::Transform& T_world_centre,
                                const ScanReductionConfig& config);

/// Scan `centre` prepared for registration together with its neighbours (PrepareScan of
/// MergeIntoFrame over SubmapMembers, window from config.submap_path_m and submap_max_scans; of
/// those, the nearest in path first while their raw points fit config.submap_max_points, the
/// centre always), in centre's sensor frame, so that a registration against it is still the
/// pose between the two scans' frames. `path_m` from SubmapPathM(poses); `load(k)` reads scan k
/// (an empty cloud for one that cannot be read), nearest first, and no farther than the budget
/// needs. Only the scan itself when the window is 0 or it has no pose.
PreparedScan PrepareSubmap(std::size_t centre, const std::vector<core::StampedPose>& poses,
                           const std::vector<double>& path_m,
                           const std::function<core::PointCloud(std::size_t)>& load,
                           const ScanReductionConfig& config);

}  // namespace lidarloop::registration

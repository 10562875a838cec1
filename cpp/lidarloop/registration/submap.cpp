#include "lidarloop/registration/submap.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

#include "lidarloop/core/min_gap.hpp"

namespace lidarloop::registration {
namespace {

bool FinitePose(const core::Transform& T) { return T.matrix().allFinite(); }

bool WithinRange(const Eigen::Vector3f& point, const ScanReductionConfig& config) {
    if (!point.allFinite()) return false;
    const double range_m = point.cast<double>().norm();
    return range_m >= config.min_range_m && range_m <= config.max_range_m;
}

// Walks from `centre` by `step` (+1 or -1) and appends the scans in the window, nearest first.
void CollectSide(const std::vector<double>& path_m, std::size_t centre, int step,
                 const SubmapWindow& window, std::vector<std::size_t>& members) {
    int taken = 0;
    for (std::size_t k = centre; taken < window.max_scans;) {
        if ((step < 0 && k == 0) || (step > 0 && k + 1 >= path_m.size())) return;
        k = step < 0 ? k - 1 : k + 1;
        if (std::isnan(path_m[k])) continue;  // no pose: cannot be placed, skip it
        if (std::abs(path_m[k] - path_m[centre]) > window.path_m) return;
        members.push_back(k);
        ++taken;
    }
}

// The members of a submap nearest in path first: the centre, then its neighbours (the earlier
// of two equally near).
std::vector<std::size_t> NearestFirst(std::vector<std::size_t> members,
                                      const std::vector<double>& path_m, std::size_t centre) {
    const auto away = [&](std::size_t k) {
        return k == centre ? -1.0 : std::abs(path_m[k] - path_m[centre]);
    };
    std::stable_sort(members.begin(), members.end(),
                     [&](std::size_t a, std::size_t b) { return away(a) < away(b); });
    return members;
}

}  // namespace

std::vector<double> SubmapPathM(const std::vector<core::StampedPose>& poses) {
    // Frames of a longer drive: its path, not the straight lines between them.
    if (core::KnowsDrivePath(poses)) {
        std::vector<double> path_m = core::CumulativePathM(poses);
        for (std::size_t i = 0; i < poses.size(); ++i)
            if (!FinitePose(poses[i].T_world_sensor))
                path_m[i] = std::numeric_limits<double>::quiet_NaN();
        return path_m;
    }
    std::vector<double> path_m(poses.size(), std::numeric_limits<double>::quiet_NaN());
    double travelled_m = 0.0;
    std::optional<Eigen::Vector3d> last;
    for (std::size_t i = 0; i < poses.size(); ++i) {
        if (!FinitePose(poses[i].T_world_sensor)) continue;
        const Eigen::Vector3d position = poses[i].T_world_sensor.translation();
        if (last) travelled_m += (position - *last).norm();
        path_m[i] = travelled_m;
        last = position;
    }
    return path_m;
}

std::vector<std::size_t> SubmapMembers(const std::vector<double>& path_m, std::size_t centre,
                                       const SubmapWindow& window) {
    std::vector<std::size_t> members;
    if (centre >= path_m.size() || std::isnan(path_m[centre])) return {centre};
    CollectSide(path_m, centre, -1, window, members);
    std::reverse(members.begin(), members.end());
    members.push_back(centre);
    if (!window.past_only) CollectSide(path_m, centre, +1, window, members);
    return members;
}

core::PointCloud MergeIntoFrame(const std::vector<core::PointCloud>& scans,
                                const std::vector<core::Transform>& T_world_scans,
                                const core::Transform& T_world_centre,
                                const ScanReductionConfig& config) {
    if (scans.size() != T_world_scans.size())
        throw std::invalid_argument("MergeIntoFrame: one pose per scan");
    core::PointCloud merged;
    if (!FinitePose(T_world_centre)) return merged;
    const core::Transform T_centre_world = T_world_centre.inverse();
    for (std::size_t i = 0; i < scans.size(); ++i) {
        if (!FinitePose(T_world_scans[i])) continue;
        const Eigen::Isometry3f T_centre_scan = (T_centre_world * T_world_scans[i]).cast<float>();
        for (const Eigen::Vector3f& point : scans[i]) {
            if (WithinRange(point, config)) merged.push_back(T_centre_scan * point);
        }
    }
    return merged;
}

PreparedScan PrepareSubmap(std::size_t centre, const std::vector<core::StampedPose>& poses,
                           const std::vector<double>& path_m,
                           const std::function<core::PointCloud(std::size_t)>& load,
                           const ScanReductionConfig& config) {
    const SubmapWindow window{config.submap_path_m, config.submap_max_scans, false};
    const std::vector<std::size_t> members = SubmapMembers(path_m, centre, window);
    if (members.size() == 1) return PrepareScan(load(centre), config);
    // Loaded nearest first until the next scan would pass the point budget (the centre always).
    std::vector<std::pair<std::size_t, core::PointCloud>> kept;
    std::size_t points = 0;
    for (const std::size_t k : NearestFirst(members, path_m, centre)) {
        core::PointCloud scan = load(k);
        if (k != centre &&
            points + scan.size() > static_cast<std::size_t>(config.submap_max_points))
            break;
        points += scan.size();
        kept.emplace_back(k, std::move(scan));
    }
    std::sort(kept.begin(), kept.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });  // merge in order
    std::vector<core::PointCloud> scans;
    std::vector<core::Transform> T_world_scans;
    Eigen::Vector3d centre_view =
        Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    for (auto& [k, scan] : kept) {
        if (k == centre) centre_view = ViewCentre(scan, config);
        scans.push_back(std::move(scan));
        T_world_scans.push_back(poses.at(k).T_world_sensor);
    }
    PreparedScan submap = PrepareScan(
        MergeIntoFrame(scans, T_world_scans, poses.at(centre).T_world_sensor, config), config);
    submap.view_centre = centre_view;  // where the centre scan looks, not its neighbours
    return submap;
}

}  // namespace lidarloop::registration

#include "lidarloop/core/point_map.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

std::string Text(double value) {
    std::ostringstream text;
    text << value;
    return text.str();
}

const MapConfig& Validated(const MapConfig& config) {
    config.Validate();
    return config;
}

}  // namespace

void MapConfig::Validate() const {
    // Written so that NaN fails too.
    if (!(voxel_m >= 0.01 && voxel_m <= 100.0)) {
        throw ConfigError("map.voxel_m must be in [0.01, 100] m, got " + Text(voxel_m));
    }
    if (max_points < 1000 || max_points > 100'000'000) {
        throw ConfigError("map.max_points must be in [1000, 100000000], got " +
                          std::to_string(max_points));
    }
}

PointMap::PointMap(const MapConfig& config) : config_(Validated(config)), grid_(config.voxel_m) {}

void PointMap::AddScan(PointsView scan, const Transform& T_world_scan, double time_s) {
    if (!T_world_scan.matrix().allFinite() || !std::isfinite(time_s)) {
        throw Error("a scan's pose or time is not finite");
    }
    placed_.clear();
    for (const Eigen::Vector3f& point : scan) {
        if (point.allFinite()) placed_.push_back(T_world_scan * point.cast<double>());
    }
    input_points_ += grid_.AddAll(placed_, time_s);
    while (grid_.size() > config_.max_points) grid_.Coarsen();
    first_time_s_ = scans_ == 0 ? time_s : std::min(first_time_s_, time_s);
    last_time_s_ = scans_ == 0 ? time_s : std::max(last_time_s_, time_s);
    ++scans_;
}

MapCloud PointMap::Cloud() const {
    MapCloud cloud;
    const std::vector<Voxel> voxels = grid_.Voxels();
    cloud.points.reserve(voxels.size());
    for (const Voxel& voxel : voxels) cloud.points.push_back({voxel.centroid, voxel.mean_value});
    cloud.voxel_m = grid_.voxel_m();
    cloud.scans = scans_;
    cloud.input_points = input_points_;
    cloud.first_time_s = first_time_s_;
    cloud.last_time_s = last_time_s_;
    return cloud;
}

}  // namespace lidarloop::core

#include "lidarloop/app/map_building.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

#include <tbb/parallel_for.h>

#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/app/run_folder.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/map_files.hpp"

namespace lidarloop::app {
namespace {

constexpr char kStage[] = "building maps";

void CheckTrajectories(const std::vector<std::vector<core::StampedPose>>& trajectories,
                       std::size_t scans) {
    for (std::size_t k = 0; k < trajectories.size(); ++k) {
        const std::string name =
            "trajectory " + std::to_string(k + 1) + " of " + std::to_string(trajectories.size());
        if (trajectories[k].size() != scans) {
            throw core::ConfigError(name + " holds " + std::to_string(trajectories[k].size()) +
                                    " poses for " + std::to_string(scans) +
                                    " scans: a map needs one pose per scan");
        }
        for (std::size_t i = 0; i < scans; ++i) {
            const core::StampedPose& pose = trajectories[k][i];
            if (!pose.T_world_sensor.matrix().allFinite() || !std::isfinite(pose.time_s)) {
                throw core::ConfigError(name + ": the pose or time of scan " + std::to_string(i) +
                                        " is not finite");
            }
        }
    }
}

std::vector<std::size_t> ScanOrder(const std::vector<std::size_t>& scans, std::size_t size) {
    if (scans.empty()) {
        std::vector<std::size_t> all(size);
        for (std::size_t i = 0; i < size; ++i) all[i] = i;
        return all;
    }
    for (const std::size_t scan : scans) {
        if (scan >= size) {
            throw core::ConfigError("scan " + std::to_string(scan) + " of a map does not exist (" +
                                    std::to_string(size) + " scans)");
        }
    }
    return scans;
}

// Scan i, or nothing when it cannot be read and `skip_bad` (the reason added to `skipped`).
std::optional<core::PointCloud> LoadScan(const io::Dataset& dataset, std::size_t i, bool skip_bad,
                                         std::vector<std::string>& skipped) {
    try {
        return dataset.LoadScan(i);
    } catch (const core::Error& e) {
        const std::string message = "scan " + std::to_string(i) + ": " + e.what();
        if (!skip_bad) throw core::Error(message);
        skipped.push_back(message);
        return std::nullopt;
    }
}

}  // namespace

std::vector<core::StampedPose> MapTrajectory(const io::Dataset& dataset,
                                             const std::filesystem::path& poses_file,
                                             const std::filesystem::path& calib_file) {
    if (!poses_file.empty()) {
        return ReadOdometry(poses_file, dataset, std::numeric_limits<double>::infinity(),
                            calib_file);
    }
    if (!calib_file.empty()) {
        throw core::ConfigError("a calibration (" + calib_file.string() +
                                ") converts a given trajectory's KITTI poses; the dataset's own "
                                "poses take its calib.txt");
    }
    if (!dataset.HasPoses()) {
        throw core::ConfigError(dataset.root().string() +
                                " has no poses: name the trajectory to place its scans with");
    }
    return dataset.poses();
}

BuiltMaps BuildMaps(const io::Dataset& dataset,
                    const std::vector<std::vector<core::StampedPose>>& trajectories,
                    const core::MapConfig& config, const MapBuildOptions& options) {
    CheckTrajectories(trajectories, dataset.size());
    const std::vector<std::size_t> order = ScanOrder(options.scans, dataset.size());
    std::vector<core::PointMap> maps(trajectories.size(), core::PointMap(config));
    BuiltMaps built;
    for (std::size_t n = 0; n < order.size(); ++n) {
        const std::size_t i = order[n];
        if (const auto scan = LoadScan(dataset, i, options.skip_bad, built.skipped)) {
            // Each map on its own core: the maps are independent, so the result is the same.
            tbb::parallel_for(std::size_t{0}, maps.size(), [&](std::size_t k) {
                const core::StampedPose& pose = trajectories[k][i];
                maps[k].AddScan(*scan, pose.T_world_sensor, pose.time_s);
            });
        }
        if (options.progress) options.progress(kStage, n + 1, order.size());
    }
    for (const core::PointMap& map : maps) built.maps.push_back(map.Cloud());
    return built;
}

std::string CoarsenedMapNote(const core::MapCloud& map, const core::MapConfig& config) {
    if (map.voxel_m <= config.voxel_m) return {};
    std::ostringstream note;
    note << "the map would hold more than map.max_points = " << config.max_points
         << " points at map.voxel_m = " << config.voxel_m << " m: its voxels are " << map.voxel_m
         << " m";
    return note.str();
}

std::string CameraFrameMapNote(const std::vector<core::StampedPose>& trajectory,
                               bool given_trajectory) {
    if (!TurnsAboutItsYAxis(trajectory)) return {};
    return std::string(
               "the trajectory turns about its y axis, as poses of a vehicle in KITTI's "
               "camera frame (y down) do: the scans stand on their side in this map; ") +
           (given_trajectory ? "give --calib CALIB (KITTI's calib.txt) to convert the poses to "
                               "the LiDAR frame"
                             : "put KITTI's calib.txt beside the scans (KITTI layout) to convert "
                               "the dataset's poses, or give them as --poses with --calib");
}

MapOutcome RunMap(const io::Dataset& dataset, const MapRequest& request) {
    const Stopwatch total;
    request.config.Validate();
    std::vector<std::filesystem::path> inputs = request.inputs;
    inputs.push_back(dataset.root());
    inputs.push_back(request.poses_file);
    inputs.push_back(request.calib_file);
    CheckOutputFile(request.out, inputs, request.overwrite);
    const std::vector<core::StampedPose> poses =
        MapTrajectory(dataset, request.poses_file, request.calib_file);
    if (request.out.has_parent_path()) PrepareOutputFolder(request.out.parent_path());
    MapBuildOptions options;
    options.progress = request.progress;
    const core::MapCloud map = BuildMaps(dataset, {poses}, request.config, options).maps.front();
    WriteFileAtomically(request.out, [&](const std::filesystem::path& temporary) {
        io::WriteMapPly(temporary, map);
    });
    MapOutcome outcome{map.points.size(), map.voxel_m, map.scans, map.input_points, {}, 0.0};
    for (std::string note : {CameraFrameMapNote(poses, !request.poses_file.empty()),
                             CoarsenedMapNote(map, request.config)}) {
        if (!note.empty()) outcome.notes.push_back(std::move(note));
    }
    outcome.total_s = total.Seconds();
    return outcome;
}

}  // namespace lidarloop::app

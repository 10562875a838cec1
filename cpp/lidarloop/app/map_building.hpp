#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "lidarloop/app/progress.hpp"
#include "lidarloop/core/point_map.hpp"
#include "lidarloop/io/dataset.hpp"

namespace lidarloop::app {

/// How BuildMaps goes over the scans.
struct MapBuildOptions {
    std::vector<std::size_t> scans;  ///< the scans to use, in this order; empty: all, in order
    /// Skip a scan that cannot be read (listed in BuiltMaps::skipped) instead of throwing.
    bool skip_bad = false;
    Progress progress;  ///< stage "building maps"
};

struct BuiltMaps {
    std::vector<core::MapCloud> maps;  ///< one per trajectory, in their order
    std::vector<std::string> skipped;  ///< "scan 12: <reason>" per skipped scan
};

/// The maps of `dataset` placed with each of `trajectories` (trajectories[k][i]: T_world_sensor
/// and time of scan i; the time colours the map), built in one pass: each scan is read once,
/// placed with every trajectory and dropped, so memory holds the maps, not the scans.
/// Deterministic. Thread-safe for distinct calls. Throws core::ConfigError for an invalid
/// `config`, a trajectory whose pose count differs from the dataset's scan count, a non-finite
/// pose or time (naming the trajectory and the scan) and a scan index out of range; core::Error
/// naming the scan when one cannot be read (unless options.skip_bad).
BuiltMaps BuildMaps(const io::Dataset& dataset,
                    const std::vector<std::vector<core::StampedPose>>& trajectories,
                    const core::MapConfig& config, const MapBuildOptions& options = {});

/// "the map holds more than map.max_points points at ...": the note of a map whose voxel edge was
/// doubled to keep to config.max_points; empty when it was not.
std::string CoarsenedMapNote(const core::MapCloud& map, const core::MapConfig& config);

/// The trajectory of a map: `poses_file` (KITTI or TUM, T_world_sensor, read as optimise reads
/// odometry, its KITTI poses converted by `calib_file`'s Tr when given; io::ReadError naming the
/// file and line of a bad pose, or the file when its pose count differs from the scans'), or
/// without one the dataset's own poses (core::ConfigError when it has none, or for a
/// `calib_file` without `poses_file`: the dataset's poses take its own calibration).
std::vector<core::StampedPose> MapTrajectory(const io::Dataset& dataset,
                                             const std::filesystem::path& poses_file,
                                             const std::filesystem::path& calib_file = {});

/// A note when the map's `trajectory` TurnsAboutItsYAxis (KITTI's camera frame): its scans would
/// stand on their side; the advice differs for a `given_trajectory` (--poses, which --calib
/// converts) and the dataset's own poses. Empty otherwise.
std::string CameraFrameMapNote(const std::vector<core::StampedPose>& trajectory,
                               bool given_trajectory);

/// What `lidarloop map` asks for.
struct MapRequest {
    /// KITTI or TUM, one pose per scan (T_world_sensor, read as optimise reads odometry). Empty:
    /// the dataset's own poses.
    std::filesystem::path poses_file;
    /// A KITTI calib.txt whose Tr converts poses_file's KITTI poses from KITTI's camera frame to
    /// the LiDAR frame (as --odometry-calib does for an odometry). Empty: taken as given.
    std::filesystem::path calib_file;
    core::MapConfig config;
    std::filesystem::path out;  ///< the PLY file to write (io::WriteMapPly)
    /// Files and folders the run reads besides the dataset folder and the poses file, which `out`
    /// may neither be nor lie inside (a calibration file, say).
    std::vector<std::filesystem::path> inputs;
    /// Replace `out` also when it is not a PLY file that lidarloop wrote.
    bool overwrite = false;
    Progress progress;
};

struct MapOutcome {
    std::size_t points = 0;          ///< points of the map written
    double voxel_m = 0.0;            ///< the voxel edge used (coarser than asked when capped)
    std::size_t scans = 0;           ///< scans placed
    std::size_t input_points = 0;    ///< finite points placed
    std::vector<std::string> notes;  ///< a coarser voxel than asked; a camera-frame trajectory
    double total_s = 0.0;
};

/// `lidarloop map`: checks request.out by the results rule for one file (CheckOutputFile: not an
/// input, not inside one, not a folder; an existing file only when lidarloop wrote it, or with
/// `overwrite`) before reading anything, reads the poses (MapTrajectory), builds the map
/// (BuildMaps) and writes it (io::WriteMapPly) so that `out` is whole or left as it was.
MapOutcome RunMap(const io::Dataset& dataset, const MapRequest& request);

}  // namespace lidarloop::app

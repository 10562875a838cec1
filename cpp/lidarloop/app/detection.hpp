#pragma once

#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "lidarloop/app/progress.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/io/prepared_scans_file.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"

namespace lidarloop::app {

/// What `lidarloop detect` asks for.
struct DetectRequest {
    io::RunConfig config;   ///< how scans are described and how loops are decided
    bool skip_bad = false;  ///< unreadable scans are listed in skipped.txt instead of stopping
    Progress progress;
    std::filesystem::path out;  ///< the results folder (created)
    /// Odometry, KITTI or TUM, one pose per scan (T_world_sensor): the path a gap in metres and
    /// loops.csv's path_m are measured on. Empty: the dataset's poses, when it has them.
    std::filesystem::path odometry_file;
    /// Instead of odometry_file, for a bag: its nav_msgs/Odometry topic, matched to the scans by
    /// their stamps (io::ReadBagOdometry).
    std::string odometry_topic;
    /// A KITTI calib.txt whose Tr converts odometry_file's KITTI poses from KITTI's camera frame
    /// to the LiDAR's (T_velo0_veloi = Tr^-1 P_i Tr, as --calib does for the poses). Empty: the
    /// file is in the LiDAR frame.
    std::filesystem::path odometry_calib;
    /// With detection.stop_at_first_loop, verification goes on after a query's first loop to
    /// the candidates that may give the pose graph a further loop of the scan
    /// (PoseGraphLoopsWanted: posegraph.max_loops_per_scan, min_loop_separation_m): optimise.
    bool pose_graph_loops = false;
};

struct DetectOutcome {
    std::vector<pipeline::LoopQuery> queries;  ///< one per scan, in scan order
    double threshold = 0.0;                    ///< the decision threshold applied
    std::size_t accepted = 0;                  ///< scans whose best match was accepted
    std::vector<std::string> skipped;          ///< "scan 17: <reason>" per skipped scan
    std::size_t map_scans = 0;                 ///< scans of the map (localisation only)
    /// Per scan, the path travelled (core::CumulativePathM of the odometry or the poses), which
    /// loops.csv's path_m is taken from; empty when neither is known and when localising.
    std::vector<double> path_m;
    /// What the run could not do as configured, e.g. submaps without poses.
    std::vector<std::string> notes;
    double total_s = 0.0;
};

/// Offline detection over a whole sequence: describes every scan, computes the similarity
/// matrix, finds each scan's candidates among the earlier scans outside the minimum gap, and
/// writes loops.csv, candidates.csv, similarity.bin, similarity.png, similarity_distance.png,
/// database.lldb (with the detection config), config.yaml, timings.json (and skipped.txt) into
/// request.out. With config.detection.verify the candidates are verified (registration::Verify)
/// and the scans reduced for it are saved as database.scans, so the map can verify too.
/// ConfigError when the gap is in seconds and there are no poses, or in metres and there is
/// neither odometry nor poses; io::ReadError when the odometry has not one pose per scan.
DetectOutcome RunDetect(const io::Dataset& dataset, const DetectRequest& request);

/// The odometry of `dataset` from `file` (KITTI or TUM, T_world_sensor): io::ReadError naming the
/// file when it has not one pose per scan (nor, for a KITTI layout, one per frame:
/// io::PosesOfFrames), or when a step between consecutive poses of the file exceeds `max_step_m` (a
/// jump or a reset). With `calib` (a KITTI calib.txt) a KITTI file is converted from KITTI's camera
/// frame by its Tr; core::ConfigError for a TUM file with `calib`. Shared by detect (the path of
/// a gap in metres) and optimise.
std::vector<core::StampedPose> ReadOdometry(
    const std::filesystem::path& file, const io::Dataset& dataset,
    double max_step_m = std::numeric_limits<double>::infinity(),
    const std::filesystem::path& calib = {});

/// The notes that say which frames of a KITTI drive the dataset's poses and `odometry` were taken
/// from (io::FramesNote), none for poses one a scan, and CameraFrameNote's of the odometry.
std::vector<std::string> FramesNotes(const io::Dataset& dataset,
                                     const std::vector<core::StampedPose>& odometry);

/// A note when a run that `verifies` (what the odometry serves) has no odometry but the
/// dataset's folder holds a poses_odometry.txt (as `simulate` writes it beside the ground truth,
/// and keyframe sets of a LIO front end ship it) that it did not read as its poses: it is not
/// read unless named by --odometry. Empty otherwise.
std::string UnusedOdometryNote(const io::Dataset& dataset,
                               const std::vector<core::StampedPose>& odometry, bool verifies);

/// Turns from the first pose smaller than this are not judged by CameraFrameNote (20 degrees).
inline constexpr double kCameraFrameMinTurnRad = 0.35;
/// The share of the turns' angles about the y axis that marks KITTI's camera frame.
inline constexpr double kCameraFrameMinAlignment = 0.9;

/// Whether the turns of `poses` from their first (those over kCameraFrameMinTurnRad) are about
/// its y axis, as a vehicle's poses in KITTI's camera frame (y down) are. False without a turn.
bool TurnsAboutItsYAxis(const std::vector<core::StampedPose>& poses);

/// A note when `odometry` TurnsAboutItsYAxis: --odometry-calib converts it. Empty otherwise.
std::string CameraFrameNote(const std::vector<core::StampedPose>& odometry);

/// The odometry of `dataset` from `file`, or, when `topic` is given, from the nav_msgs/Odometry
/// messages of `topic` in the dataset's bag, interpolated at the scans' stamps
/// (io::ReadBagOdometry: io::ReadError naming the bag and the topic when their times do not
/// cover the scans). core::ConfigError for a topic with a dataset that is no bag, or both, and for
/// a topic with `calib` (it converts a file's KITTI poses).
std::vector<core::StampedPose> ReadOdometry(
    const std::filesystem::path& file, const std::string& topic, const io::Dataset& dataset,
    double max_step_m = std::numeric_limits<double>::infinity(),
    const std::filesystem::path& calib = {});

/// ReadOdometry when a file, a topic or a calibration is given (its errors too), else no
/// odometry (empty): how detect, evaluate and bench take their optional odometry.
std::vector<core::StampedPose> ReadOdometryIfGiven(const std::filesystem::path& file,
                                                   const std::string& topic,
                                                   const io::Dataset& dataset, double max_step_m,
                                                   const std::filesystem::path& calib);

/// How odometry was given, for reports: the file, or "BAG topic '/odom'".
std::string OdometryName(const std::filesystem::path& file, const std::string& topic,
                         const io::Dataset& dataset);

/// A saved descriptor database to localise against.
struct LoadedMap {
    std::filesystem::path file;
    pipeline::DescriptorDatabase database;
    /// The detection config the map was saved with: its threshold is the one to localise with
    /// unless the request sets another.
    pipeline::DetectorConfig detection;
    /// The map's scans reduced for verification (io::PreparedScansPathOf the file), when saved.
    std::optional<io::StoredPreparedScans> scans;
    double load_s = 0.0;
};

/// Loads a database.lldb written by RunDetect, and its database.scans when present
/// (io::ReadError naming what is wrong).
LoadedMap LoadMap(const std::filesystem::path& file);

/// Writes `detector`'s stored scans as a map LoadMap reads: `file` (.lldb, with the detection
/// config) and, when scans were kept for verification, io::PreparedScansPathOf(file) (else an
/// earlier map's prepared scans there are removed, so that they are not loaded as this one's;
/// another file of that name stays). core::ConfigError for a `file` named .scans. Both
/// record submap_path_m 0: the online detector prepares every scan alone, and RunLocalise
/// prepares its queries as the map's scans were. io::WriteError when it cannot write.
void SaveDetectorMap(const pipeline::LoopDetector& detector, const std::filesystem::path& file);

/// Localisation: every scan of `dataset` is searched in `map` and not added to it.
/// request.config.descriptor must equal the map's (ConfigError otherwise): scans are described
/// as the map's were; its detection keys apply, and without a threshold the map's saved one
/// (map.detection.threshold) does, else the method's default. Writes loops.csv (query scan, map
/// scan), candidates.csv, config.yaml, timings.json (and skipped.txt) into request.out.
/// With config.detection.verify the candidates are verified against the map's prepared scans:
/// ConfigError when the map has none or they were reduced with another configuration.
DetectOutcome RunLocalise(const io::Dataset& dataset, LoadedMap map, const DetectRequest& request);

}  // namespace lidarloop::app

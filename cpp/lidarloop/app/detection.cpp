#include "lidarloop/app/detection.hpp"

#include <atomic>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>

#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/app/optimisation.hpp"
#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/app/verification_run.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/io/database_file.hpp"
#include "lidarloop/io/png.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/io/prepared_scans_file.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/rosbag.hpp"
#include "lidarloop/io/similarity_file.hpp"
#include "lidarloop/io/similarity_image.hpp"

namespace lidarloop::app {
namespace {

void RequireTimesForSeconds(const io::RunConfig& config, const io::Dataset& dataset) {
    if (config.detection.min_gap.unit == core::MinGap::Unit::kSeconds && !dataset.HasTimes()) {
        throw core::ConfigError("a minimum gap in seconds needs scan times, and " +
                                dataset.root().string() +
                                " has no poses and no times.txt; give --poses or a gap in scans");
    }
}

// The odometry of the scans when given (--odometry, --odometry-topic), else empty: what places
// a scan's neighbours in its submap. Never the dataset's poses: in KITTI layout they are the
// ground truth, and submaps placed by them would let the truth into the verification that is
// then scored against it.
std::vector<core::StampedPose> OdometryOfScans(const DetectRequest& request,
                                               const io::Dataset& dataset) {
    return ReadOdometryIfGiven(request.odometry_file, request.odometry_topic, dataset,
                               std::numeric_limits<double>::infinity(), request.odometry_calib);
}

// Per scan, the path travelled (core::CumulativePathM): on the odometry when given, else on the
// dataset's poses; empty when there are neither (ConfigError when the gap is in metres).
std::vector<double> PathOfScans(const DetectRequest& request, const io::Dataset& dataset,
                                const std::vector<core::StampedPose>& odometry) {
    std::vector<double> path_m =
        core::CumulativePathM(odometry.empty() && dataset.HasPoses() ? dataset.poses() : odometry);
    if (path_m.empty() && request.config.detection.min_gap.unit == core::MinGap::Unit::kMetres) {
        throw core::ConfigError("a minimum gap in metres needs the path travelled, and " +
                                dataset.root().string() +
                                " has no poses; give --odometry FILE, --poses or a gap in scans");
    }
    return path_m;
}

// Without poses or odometry no candidate can be held to detection.min_path_m: a slow platform's
// recent past passes the gap in scans alone.
std::string NoPathNote() {
    return "no path rule (detection.min_path_m): the dataset has no poses and no --odometry was "
           "given, so a candidate need only lie outside the gap in scans; a slow platform's "
           "recent past may then count as a loop";
}

// When no scan of a sequence of several has a single candidate: nothing was compared, so nothing
// can be found (e.g. a gap longer than the sequence), which a run must say.
std::string NoCandidateNote(const std::vector<pipeline::LoopQuery>& queries,
                            const pipeline::DetectorConfig& detector, bool odometry) {
    if (queries.size() < 2) return {};
    for (const pipeline::LoopQuery& query : queries) {
        if (query.has_match()) return {};
    }
    return "no scan had a candidate: every earlier scan lies within the minimum gap "
           "(detection.min_gap: " +
           core::NumberText(detector.min_gap.value) + " " + core::ToString(detector.min_gap.unit) +
           ") or fails the path rule (detection.min_path_m: " +
           core::NumberText(detector.min_path_m) + " m)" +
           (odometry ? " or lies out of a loop's reach by the odometry" : "");
}

}  // namespace

bool TurnsAboutItsYAxis(const std::vector<core::StampedPose>& poses) {
    // A ground vehicle turns about its up axis: z in the LiDAR frame, y in KITTI's camera frame
    // (y down). Each pose's turn from the first, weighted by its angle.
    double about_y = 0.0, about_any = 0.0;
    for (std::size_t i = 1; i < poses.size(); ++i) {
        const Eigen::AngleAxisd turn(poses.front().T_world_sensor.linear().transpose() *
                                     poses[i].T_world_sensor.linear());
        if (!turn.axis().allFinite() || turn.angle() < kCameraFrameMinTurnRad) continue;
        about_y += turn.angle() * std::abs(turn.axis().y());
        about_any += turn.angle();
    }
    return about_any > 0.0 && about_y >= kCameraFrameMinAlignment * about_any;
}

std::string CameraFrameNote(const std::vector<core::StampedPose>& odometry) {
    if (!TurnsAboutItsYAxis(odometry)) return {};
    return "the odometry turns about its y axis, as poses of a vehicle in KITTI's camera frame "
           "(y down) do: give --odometry-calib CALIB to convert them to the LiDAR frame, or the "
           "odometry gate will reject right loops";
}

std::vector<std::string> FramesNotes(const io::Dataset& dataset,
                                     const std::vector<core::StampedPose>& odometry) {
    std::vector<std::string> notes;
    for (const auto& [poses, what] :
         {std::pair{&dataset.poses(), "poses"}, std::pair{&odometry, "odometry"}}) {
        std::string note = io::FramesNote(dataset.ScanPaths(), *poses, what);
        if (!note.empty()) notes.push_back(std::move(note));
    }
    if (std::string note = CameraFrameNote(odometry); !note.empty())
        notes.push_back(std::move(note));
    return notes;
}

std::string UnusedOdometryNote(const io::Dataset& dataset,
                               const std::vector<core::StampedPose>& odometry, bool verifies) {
    if (!verifies || !odometry.empty()) return {};
    std::error_code error;
    const std::filesystem::path file = dataset.root() / "poses_odometry.txt";
    if (!std::filesystem::is_regular_file(file, error)) return {};
    for (const std::filesystem::path& read : dataset.InputFiles()) {
        if (std::filesystem::equivalent(read, file, error)) return {};  // given as the poses
    }
    return file.string() +
           " is not read: give it as the odometry (--odometry FILE; odometry= "
           "in Python) if it is the scans' odometry (it places submaps and "
           "checks loops, docs/cli.md)";
}

std::vector<core::StampedPose> ReadOdometry(const std::filesystem::path& file,
                                            const io::Dataset& dataset, double max_step_m,
                                            const std::filesystem::path& calib) {
    if (!calib.empty() && io::IsTumPosesFile(file)) {
        throw core::ConfigError("an odometry calibration (" + calib.string() +
                                ") converts KITTI poses, and " + file.string() +
                                " is a TUM file: give TUM poses in the LiDAR frame");
    }
    const core::Transform T_cam0_velo =
        calib.empty() ? core::Transform::Identity() : io::ReadKittiCalibTr(calib);
    std::vector<core::StampedPose> odometry = io::ReadPoses(file, T_cam0_velo, {}, max_step_m);
    if (dataset.format() == io::DatasetFormat::kKitti) {
        odometry = io::PosesOfFrames(dataset.ScanPaths(), std::move(odometry), file);
    }
    if (odometry.size() != dataset.size()) {
        throw io::ReadError(file,
                            "holds " + std::to_string(odometry.size()) + " poses but " +
                                dataset.root().string() + " has " + std::to_string(dataset.size()) +
                                " scans: odometry needs one pose per scan" +
                                (dataset.format() == io::DatasetFormat::kKitti
                                     ? io::PosesOfFramesHint(dataset.ScanPaths(), odometry.size())
                                     : std::string()));
    }
    // A KITTI file has no times (ReadPoses numbers the poses): they are the scans' own, so that
    // poses written with times (optimise --format tum) carry the dataset's.
    if (!io::IsTumPosesFile(file) && dataset.HasTimes()) {
        for (std::size_t i = 0; i < odometry.size(); ++i) odometry[i].time_s = dataset.ScanTime(i);
    }
    return odometry;
}

std::vector<core::StampedPose> ReadOdometry(const std::filesystem::path& file,
                                            const std::string& topic, const io::Dataset& dataset,
                                            double max_step_m, const std::filesystem::path& calib) {
    if (file.empty() && topic.empty() && !calib.empty()) {
        throw core::ConfigError("an odometry calibration (" + calib.string() +
                                ") converts an odometry file: give --odometry FILE");
    }
    if (topic.empty()) return ReadOdometry(file, dataset, max_step_m, calib);
    if (!file.empty()) {
        throw core::ConfigError("odometry from a file (" + file.string() + ") and from topic " +
                                core::Quoted(topic) + ": give one");
    }
    if (!calib.empty()) {
        throw core::ConfigError("an odometry calibration (" + calib.string() +
                                ") converts a file's KITTI poses, not topic " +
                                core::Quoted(topic) + "'s");
    }
    if (dataset.format() != io::DatasetFormat::kRosbag) {
        throw core::ConfigError("an odometry topic (" + core::Quoted(topic) +
                                ") needs a bag, and " + dataset.root().string() +
                                " is a folder; give an odometry file");
    }
    std::vector<double> times_s(dataset.size());
    for (std::size_t i = 0; i < times_s.size(); ++i) times_s[i] = dataset.ScanTime(i);
    return io::ReadBagOdometry(dataset.root(), topic, times_s, max_step_m);
}

std::vector<core::StampedPose> ReadOdometryIfGiven(const std::filesystem::path& file,
                                                   const std::string& topic,
                                                   const io::Dataset& dataset, double max_step_m,
                                                   const std::filesystem::path& calib) {
    if (file.empty() && topic.empty() && calib.empty()) return {};
    return ReadOdometry(file, topic, dataset, max_step_m, calib);
}

namespace {

// With submaps, replaces each prepared scan by its submap.
void PrepareSubmapsIfAsked(const io::Dataset& dataset, const io::RunConfig& config,
                           const std::vector<core::StampedPose>& poses,
                           const DetectRequest& request, PreparedScans& prepared) {
    if (!config.detection.verify) return;
    app::PrepareSubmapsIfAsked(dataset, poses, config.detection.verification, prepared,
                               request.progress);
}

}  // namespace

std::string OdometryName(const std::filesystem::path& file, const std::string& topic,
                         const io::Dataset& dataset) {
    if (topic.empty()) return file.string();
    return dataset.root().string() + " topic " + core::Quoted(topic);
}

namespace {

// A note of how many of the queries' candidates were rejected for `reason`, when any were.
void NoteRejected(DetectOutcome& outcome, registration::RejectReason reason,
                  const std::string& what) {
    const std::size_t count = CountRejected(outcome.queries, reason);
    if (count > 0) outcome.notes.push_back(std::to_string(count) + what);
}

// `matrix` is null when the sequence was detected without one (output.similarity_matrix_mib).
void WriteDetectResults(const std::filesystem::path& out_dir, const io::RunConfig& config,
                        const pipeline::SequenceDescriptors& described,
                        const pipeline::SimilarityMatrix* matrix, const DetectOutcome& outcome,
                        const PreparedScans& prepared, const std::vector<double>& path_m) {
    const core::Method method = config.descriptor.method;
    WriteLoopsCsv(out_dir / "loops.csv", outcome.queries, path_m);
    WriteCandidatesCsv(out_dir / "candidates.csv", outcome.queries, path_m);
    if (matrix != nullptr) {
        io::WriteSimilarityMatrix(out_dir / "similarity.bin", *matrix, method);
        io::WritePng(out_dir / "similarity.png",
                     io::ThresholdImage(*matrix, method, outcome.threshold));
        io::WritePng(out_dir / "similarity_distance.png", io::DistanceImage(*matrix));
    }
    WriteSkipped(out_dir, described.skipped);
    io::SaveDatabase(out_dir / "database.lldb", described.database, config.detection);
    if (config.detection.verify) {
        io::SavePreparedScans(out_dir / "database.scans", prepared.scans,
                              config.detection.verification.reduction);
    }
}

// The map's prepared scans for verifying against it, checked against the run's reduction.
std::vector<registration::PreparedScan> MapScansFor(LoadedMap& map,
                                                    const pipeline::DetectorConfig& detection) {
    if (!detection.verify) return {};
    const std::filesystem::path scans_file = io::PreparedScansPathOf(map.file);
    if (!map.scans) {
        throw core::ConfigError("the map " + map.file.string() + " has no prepared scans (" +
                                scans_file.string() +
                                ") to verify candidates against: rebuild it with `lidarloop "
                                "detect` (which verifies by default), or localise with "
                                "--no-verify");
    }
    // Whether the map's scans are submaps is the map's affair: RunLocalise prepares the queries
    // as the map's scans were, and a scan registers to a submap in its frame.
    registration::ScanReductionConfig reduction = detection.verification.reduction;
    reduction.submap_path_m = map.scans->reduction.submap_path_m;
    reduction.submap_max_scans = map.scans->reduction.submap_max_scans;
    reduction.submap_max_points = map.scans->reduction.submap_max_points;
    if (map.scans->reduction != reduction) {
        throw core::ConfigError("verification.reduction differs from the one " +
                                scans_file.string() +
                                " was made with; localise with the map's (its config.yaml)");
    }
    if (map.scans->scans.size() != map.database.size()) {
        throw core::ConfigError(scans_file.string() + " holds " +
                                std::to_string(map.scans->scans.size()) + " scans, the map " +
                                std::to_string(map.database.size()));
    }
    return std::move(map.scans->scans);
}

// Describes every scan of `dataset`; with verification, also prepares each scan for
// registration into `prepared` in the same pass (one read per scan): alone, or only marked as
// read where the odometry's submaps replace them (`odometry`).
pipeline::SequenceDescriptors DescribeAndPrepare(const io::Dataset& dataset,
                                                 const io::RunConfig& config,
                                                 const DetectRequest& request,
                                                 PreparedScans& prepared, bool odometry) {
    DescribeRun run{
        "describing", request.skip_bad, pipeline::Execution::kParallel, request.progress, {}};
    const auto& reduction = config.detection.verification.reduction;
    if (config.detection.verify)
        run.with_cloud =
            odometry ? prepared.CollectorFor(reduction) : prepared.Collector(reduction);
    return DescribeDataset(dataset, config.descriptor, run);
}

}  // namespace

DetectOutcome RunDetect(const io::Dataset& dataset, const DetectRequest& request) {
    request.config.Validate();
    const std::vector<core::StampedPose> poses = OdometryOfScans(request, dataset);
    DetectOutcome outcome;
    outcome.notes = FramesNotes(dataset, poses);
    if (std::string note = UnusedOdometryNote(dataset, poses, request.config.detection.verify);
        !note.empty())
        outcome.notes.push_back(std::move(note));
    const io::RunConfig config =
        WithSubmapsWhereTheyApply(request.config, dataset, poses, outcome.notes,
                                  NeighboursPlaceSubmaps(dataset, poses), true);
    const double threshold = config.detection.ThresholdFor(config.descriptor.method);
    pipeline::MethodOf(config.descriptor.method).ValidateThreshold(threshold);
    RequireTimesForSeconds(config, dataset);
    const std::vector<double> path_m = PathOfScans(request, dataset, poses);
    if (path_m.empty() && config.detection.min_path_m > 0.0) outcome.notes.push_back(NoPathNote());
    const std::filesystem::path out_dir = PrepareOutputFolder(request.out);
    io::WriteConfigYaml(out_dir / "config.yaml", config);

    Stopwatch total;
    Stopwatch describe_clock;
    const bool verify = config.detection.verify;
    PreparedScans prepared(verify ? dataset.size() : 0);
    const pipeline::SequenceDescriptors described =
        DescribeAndPrepare(dataset, config, request, prepared, !poses.empty());
    PrepareSubmapsIfAsked(dataset, config, poses, request, prepared);
    const double describe_s = describe_clock.Seconds();

    // Where the odometry judges the loops, the scans out of a loop's reach are no candidates.
    std::atomic<std::size_t> rejected{0};
    pipeline::LoopCheck check = verify
                                    ? ScansOwnCheck(prepared, config.detection.verification.coarse)
                                    : pipeline::LoopCheck{};
    if (verify && !poses.empty())
        check = OdometryLoopCheck(poses, path_m, config.posegraph, &rejected, &prepared);
    // All pairs either way; the matrix only when it fits the budget (same results without).
    Stopwatch matrix_clock;
    std::optional<pipeline::SimilarityMatrix> matrix;
    outcome.threshold = threshold;
    outcome.path_m = path_m;
    if (config.output.KeepsSimilarityMatrix(dataset.size())) {
        matrix = pipeline::ComputeSimilarityMatrix(described.database);
        outcome.queries =
            pipeline::DetectFromMatrix(*matrix, described.database.times_s(), config.detection,
                                       config.descriptor.method, path_m, check);
    } else {
        outcome.queries = pipeline::DetectStreaming(described.database, config.detection,
                                                    pipeline::Execution::kParallel, path_m, check);
    }
    const double matrix_s = matrix_clock.Seconds();
    if (std::string note = NoCandidateNote(outcome.queries, config.detection, !poses.empty());
        !note.empty()) {
        outcome.notes.push_back(std::move(note));
    }
    Stopwatch verify_clock;
    pipeline::VerificationTimes verification_times;
    if (verify) {
        pipeline::MoreLoopsWanted more;
        if (request.pose_graph_loops) more = PoseGraphLoopsWanted(path_m, config.posegraph);
        verification_times =
            VerifyAll(outcome.queries, prepared, config.detection, config.descriptor.method,
                      request.progress, nullptr, check, more);
        if (rejected > 0) {
            outcome.notes.push_back(
                std::to_string(rejected) +
                " registered candidates rejected: the odometry contradicts their pose beyond its "
                "drift (reason odometry_mismatch in candidates.csv; the gate of posegraph.robust)");
        }
        NoteRejected(outcome, registration::RejectReason::kUnlikeNeighbours,
                     " registered candidates rejected: they overlap far less than their scans do "
                     "with their neighbours, as a look-alike place does (reason unlike_neighbours "
                     "in candidates.csv; verification.acceptance.min_neighbour_overlap_ratio)");
        NoteRejected(outcome, registration::RejectReason::kUnlikeMotion,
                     " registered candidates rejected: the scans between match and query, each "
                     "registered to the one before, put them too far apart for a loop (reason "
                     "unlike_motion in candidates.csv; verification.acceptance.motion_*)");
        NoteRejected(outcome, registration::RejectReason::kUnlikeFits,
                     " registered candidates rejected: more of their query's fits on candidates "
                     "ranked before them place the query elsewhere by the odometry (reason "
                     "unlike_fits in candidates.csv)");
        NoteRejected(outcome, registration::RejectReason::kUnlikeRevisit,
                     " loops rejected: a longer chain of agreeing loops of their revisit places "
                     "them elsewhere by the odometry (reason unlike_revisit in candidates.csv; "
                     "verification.acceptance.revisit_path_m)");
    }
    const double verify_s = verify_clock.Seconds();
    outcome.accepted = CountAccepted(outcome.queries);
    outcome.skipped = described.skipped;
    WriteDetectResults(out_dir, config, described, matrix ? &*matrix : nullptr, outcome, prepared,
                       path_m);

    const std::size_t n = dataset.size();
    nlohmann::json timings = TimingsJson(described, n > 1 ? n * (n - 1) / 2 : 0, matrix_s);
    timings["similarity_matrix_kept"] = matrix.has_value();
    timings["describe_total_s"] = describe_s;
    if (verify) {
        timings["verification"] = VerificationTimingsJson(prepared, verification_times);
        timings["verification"]["total_s"] = verify_s;
    }
    outcome.total_s = total.Seconds();
    timings["total_s"] = outcome.total_s;
    WriteJson(out_dir / "timings.json", timings);
    return outcome;
}

LoadedMap LoadMap(const std::filesystem::path& file) {
    Stopwatch clock;
    io::StoredDatabase stored = io::LoadStoredDatabase(file);
    std::optional<io::StoredPreparedScans> scans;
    const std::filesystem::path scans_file = io::PreparedScansPathOf(file);
    if (std::filesystem::exists(scans_file)) scans = io::LoadPreparedScans(scans_file);
    return {file, std::move(stored.database), stored.detection, std::move(scans), clock.Seconds()};
}

void SaveDetectorMap(const pipeline::LoopDetector& detector, const std::filesystem::path& file) {
    const std::filesystem::path scans_file = io::PreparedScansPathOf(file);
    if (scans_file == file) {
        throw core::ConfigError(file.string() +
                                " is where a map's prepared scans go; save the "
                                "map as a .lldb file");
    }
    pipeline::DetectorConfig detection = detector.detector_config();
    detection.verification.reduction.submap_path_m = 0.0;  // LoopDetector verifies scans alone
    io::SaveDatabase(file, detector.database(), detection);
    const auto& scans = detector.prepared_scans();
    if (std::any_of(scans.begin(), scans.end(), [](const auto& scan) { return scan.prepared(); })) {
        io::SavePreparedScans(scans_file, scans, detection.verification.reduction);
    } else if (io::IsPreparedScansFile(scans_file)) {
        // An earlier map's prepared scans would otherwise be loaded as this one's.
        std::error_code error;
        if (!std::filesystem::remove(scans_file, error) && error) {
            throw io::WriteError(scans_file,
                                 "an earlier map's prepared scans, which would be "
                                 "taken for this map's, cannot be removed: " +
                                     error.message());
        }
    }
}

DetectOutcome RunLocalise(const io::Dataset& dataset, LoadedMap map, const DetectRequest& request) {
    Stopwatch total;
    const std::vector<core::StampedPose> poses = OdometryOfScans(request, dataset);
    DetectOutcome outcome;
    outcome.notes = FramesNotes(dataset, poses);
    // The queries are prepared as the map's scans were, submaps or alone: a submap on one side
    // only shows much its partner never saw.
    const bool map_of_submaps = map.scans && map.scans->reduction.submap_path_m > 0.0;
    io::RunConfig asked = request.config;
    if (map.scans && !map_of_submaps && asked.detection.verify &&
        asked.detection.verification.reduction.submap_path_m > 0.0) {
        asked.detection.verification.reduction.submap_path_m = 0.0;
        outcome.notes.push_back(
            "no submaps (verification.reduction.submap_path_m): the map's scans are alone, so "
            "each query is verified alone too");
    }
    io::RunConfig config =
        WithSubmapsWhereTheyApply(asked, dataset, poses, outcome.notes,
                                  map_of_submaps && NeighboursPlaceSubmaps(dataset, poses), false);
    if (!config.detection.threshold) config.detection.threshold = map.detection.threshold;
    config.Validate();
    if (config.descriptor != map.database.config()) {
        throw core::ConfigError("the configuration changes how scans are described, but the map " +
                                map.file.string() + " fixes that");
    }
    std::vector<registration::PreparedScan> map_scans = MapScansFor(map, config.detection);
    const pipeline::LoopDetector detector(std::move(map.database), config.detection,
                                          std::move(map_scans));
    const std::filesystem::path out_dir = PrepareOutputFolder(request.out);
    io::WriteConfigYaml(out_dir / "config.yaml", config);

    const bool verify = config.detection.verify;
    PreparedScans prepared(verify ? dataset.size() : 0);
    const pipeline::SequenceDescriptors described =
        DescribeAndPrepare(dataset, config, request, prepared, !poses.empty());
    PrepareSubmapsIfAsked(dataset, config, poses, request, prepared);
    Stopwatch query_clock;
    outcome.queries = pipeline::LocaliseSequence(detector, described.database,
                                                 pipeline::Execution::kParallel, prepared.scans);
    const double query_s = query_clock.Seconds();
    outcome.threshold = detector.threshold();
    outcome.map_scans = detector.database().size();
    outcome.accepted = CountAccepted(outcome.queries);
    outcome.skipped = described.skipped;

    WriteLoopsCsv(out_dir / "loops.csv", outcome.queries);
    WriteCandidatesCsv(out_dir / "candidates.csv", outcome.queries);
    WriteSkipped(out_dir, described.skipped);
    nlohmann::json timings = DescribeTimingsJson(described);
    timings["map"] = map.file.string();
    timings["map_scans"] = detector.database().size();
    timings["load_map_s"] = map.load_s;
    if (verify) {
        timings["prepare_ms_per_scan"] = SummaryJson(prepared.prepare_seconds, 1e3);
        timings["map_prepared_bytes_per_scan"] =
            detector.database().size() == 0 ? 0.0
                                            : static_cast<double>(detector.prepared_bytes()) /
                                                  static_cast<double>(detector.database().size());
    }
    timings["query_ms_per_scan_wall"] =
        outcome.queries.empty() ? 0.0 : 1e3 * query_s / static_cast<double>(outcome.queries.size());
    outcome.total_s = total.Seconds() + map.load_s;
    timings["total_s"] = outcome.total_s;
    WriteJson(out_dir / "timings.json", timings);
    return outcome;
}

}  // namespace lidarloop::app

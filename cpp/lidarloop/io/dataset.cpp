#include "lidarloop/io/dataset.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <optional>
#include <string_view>

#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/io/osnabrueck.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/rosbag.hpp"
#include "lidarloop/io/run_record.hpp"
#include "lidarloop/io/scan_reader.hpp"

namespace lidarloop::io {
namespace fs = std::filesystem;
namespace {

// "scan2" < "scan10": runs of digits compare by value, so unpadded numbering sorts as expected.
bool NaturalLess(const std::string& a, const std::string& b) {
    std::size_t i = 0;
    std::size_t j = 0;
    while (i < a.size() && j < b.size()) {
        if (std::isdigit(static_cast<unsigned char>(a[i])) &&
            std::isdigit(static_cast<unsigned char>(b[j]))) {
            std::size_t i_end = i;
            std::size_t j_end = j;
            while (i_end < a.size() && std::isdigit(static_cast<unsigned char>(a[i_end]))) ++i_end;
            while (j_end < b.size() && std::isdigit(static_cast<unsigned char>(b[j_end]))) ++j_end;
            std::string_view da = std::string_view(a).substr(i, i_end - i);
            std::string_view db = std::string_view(b).substr(j, j_end - j);
            while (da.size() > 1 && da.front() == '0') da.remove_prefix(1);
            while (db.size() > 1 && db.front() == '0') db.remove_prefix(1);
            if (da.size() != db.size()) return da.size() < db.size();
            if (da != db) return da < db;
            i = i_end;
            j = j_end;
        } else {
            if (a[i] != b[j]) return a[i] < b[j];
            ++i;
            ++j;
        }
    }
    return a.size() - i < b.size() - j;
}

std::vector<fs::path> ListFiles(const fs::path& folder, bool (*accept)(const fs::path&)) {
    std::vector<fs::path> files;
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) return files;
    for (const auto& entry : fs::directory_iterator(folder)) {
        if (entry.is_regular_file() && accept(entry.path())) files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
        return NaturalLess(a.filename().string(), b.filename().string());
    });
    return files;
}

bool IsKittiBin(const fs::path& file) { return file.extension() == ".bin"; }

bool IsOsnabrueckScan(const fs::path& file) {
    return file.extension() == ".3d" && file.filename().string().rfind("scan", 0) == 0;
}

bool IsFolderScan(const fs::path& file) {
    return IsScanFile(file) && !IsSidecarFile(file) && file.extension() != ".3d";
}

// A folder's scans. Where scans of another format lie beside .txt files, those are notes or poses
// (groundtruth.txt, odom.txt): ASCII point clouds are not mixed with binary scans.
std::vector<fs::path> ListFolderScans(const fs::path& root) {
    auto scans = ListFiles(root, IsFolderScan);
    const auto is_text = [](const fs::path& file) { return file.extension() == ".txt"; };
    if (!std::all_of(scans.begin(), scans.end(), is_text)) {
        scans.erase(std::remove_if(scans.begin(), scans.end(), is_text), scans.end());
    }
    return scans;
}

fs::path ExistingOr(const fs::path& given, const fs::path& fallback) {
    if (!given.empty()) return given;
    std::error_code ec;
    return fs::exists(fallback, ec) ? fallback : fs::path();
}

// A poses file given or found that holds no pose is an error: read as "no poses" it would
// silently drop the path rule and the evaluation, and a --poses file would hide poses.txt.
std::vector<core::StampedPose> ReadPosesFile(const fs::path& file,
                                             const core::Transform& T_cam0_velo,
                                             const fs::path& times_file) {
    std::vector<core::StampedPose> poses = ReadPoses(file, T_cam0_velo, times_file);
    if (poses.empty()) throw ReadError(file, "holds no poses");
    return poses;
}

// A frame number too large for any drive: the names of longer numbers read as it.
constexpr std::size_t kFrameBeyondAnyDrive = 999'999'999;

// The frame number of a KITTI scan file (velodyne/000094.bin is frame 94; KITTI-360's
// 0000000094.bin too), if its name is one.
std::optional<std::size_t> FrameNumber(const fs::path& scan) {
    const std::string stem = scan.stem().string();
    std::string_view digits = stem;
    if (digits.empty() || !std::all_of(digits.begin(), digits.end(), [](char c) {
            return std::isdigit(static_cast<unsigned char>(c)) != 0;
        })) {
        return std::nullopt;
    }
    while (digits.size() > 1 && digits.front() == '0') digits.remove_prefix(1);
    if (digits.size() > 9) return kFrameBeyondAnyDrive;
    return static_cast<std::size_t>(std::stoul(std::string(digits)));
}

// The scans' frame numbers when every scan is named by one, in the scans' order.
std::optional<std::vector<std::size_t>> FrameNumbers(const std::vector<fs::path>& scans) {
    std::vector<std::size_t> frames;
    frames.reserve(scans.size());
    for (const fs::path& scan : scans) {
        const std::optional<std::size_t> frame = FrameNumber(scan);
        if (!frame) return std::nullopt;
        frames.push_back(*frame);
    }
    return frames;
}

// Frames 0 to n - 1: a whole sequence (or its beginning), whose poses file has one pose a scan.
bool FirstFrames(const std::vector<std::size_t>& frames) {
    for (std::size_t i = 0; i < frames.size(); ++i)
        if (frames[i] != i) return false;
    return true;
}

// The frames whose `count` rows of `file` (poses or times, one a frame of the drive) the scans
// take (PosesOfFrames' rule); nullopt when the rows are one a scan as given. ReadError naming
// `file` for a frame beyond its rows, naming a scan whose frame the one before has too.
std::optional<std::vector<std::size_t>> FramesToPick(const std::vector<fs::path>& scans,
                                                     std::size_t count, const std::string& rows,
                                                     const fs::path& file) {
    if (count <= scans.size()) return std::nullopt;
    std::optional<std::vector<std::size_t>> frames = FrameNumbers(scans);
    if (!frames || FirstFrames(*frames)) return std::nullopt;
    for (std::size_t i = 0; i < frames->size(); ++i) {
        const std::size_t frame = (*frames)[i];
        if (frame >= count) {
            throw ReadError(
                file, "holds " + std::to_string(count) + " " + rows + " (frames 0 to " +
                          std::to_string(count - 1) + ") but scan " + scans[i].filename().string() +
                          " is " +
                          (frame == kFrameBeyondAnyDrive ? std::string("a later frame")
                                                         : "frame " + std::to_string(frame)));
        }
        if (i > 0 && frame == (*frames)[i - 1]) {
            throw ReadError(scans[i], "is frame " + std::to_string(frame) + ", as is " +
                                          scans[i - 1].filename().string());
        }
    }
    return frames;
}

// A folder's times.txt when it has no poses (KITTI gives times for every sequence, poses for
// some): one time a scan, or for some frames of a KITTI drive one a frame; empty without one.
std::vector<double> TimesOfScans(const std::vector<fs::path>& scans, const fs::path& times_file,
                                 bool by_frame) {
    if (times_file.empty() || scans.empty()) return {};
    std::vector<double> times_s = ReadKittiTimes(times_file);
    const std::optional<std::vector<std::size_t>> frames =
        by_frame ? FramesToPick(scans, times_s.size(), "times", times_file) : std::nullopt;
    if (frames) {
        std::vector<double> selected;
        for (const std::size_t frame : *frames) selected.push_back(times_s[frame]);
        times_s = std::move(selected);
    }
    if (times_s.size() != scans.size()) {
        throw ReadError(times_file, "holds " + std::to_string(times_s.size()) + " times for " +
                                        std::to_string(scans.size()) + " scans");
    }
    return times_s;
}

Dataset OpenKitti(const fs::path& root, const DatasetOptions& options) {
    auto scans = ListFiles(root / "velodyne", IsKittiBin);
    const fs::path poses_file = ExistingOr(options.poses_file, root / "poses.txt");
    const fs::path calib_file = ExistingOr(options.calib_file, root / "calib.txt");
    const fs::path times_file = ExistingOr({}, root / "times.txt");
    if (poses_file.empty()) {
        std::vector<double> times_s = TimesOfScans(scans, times_file, /*by_frame=*/true);
        return {DatasetFormat::kKitti, root, std::move(scans), {}, std::move(times_s)};
    }
    const core::Transform T_cam0_velo =
        calib_file.empty() ? core::Transform::Identity() : ReadKittiCalibTr(calib_file);
    std::vector<core::StampedPose> poses =
        PosesOfFrames(scans, ReadPosesFile(poses_file, T_cam0_velo, times_file), poses_file);
    return {DatasetFormat::kKitti, root, std::move(scans), std::move(poses)};
}

Dataset OpenOsnabrueck(const fs::path& root, const DatasetOptions& options) {
    auto scans = ListFiles(root, IsOsnabrueckScan);
    std::vector<core::StampedPose> poses;
    if (!options.poses_file.empty()) {
        poses = ReadPosesFile(options.poses_file, core::Transform::Identity(), {});
    } else {
        // Prefer the registered .frames poses (the repository's ground truth) over .pose guesses.
        for (std::size_t i = 0; i < scans.size(); ++i) {
            fs::path frames = scans[i];
            fs::path pose = scans[i];
            frames.replace_extension(".frames");
            pose.replace_extension(".pose");
            std::error_code ec;
            core::StampedPose stamped;
            stamped.time_s = static_cast<double>(i);
            if (fs::exists(frames, ec)) {
                stamped.T_world_sensor = ReadOsnabrueckFrames(frames);
            } else if (fs::exists(pose, ec)) {
                stamped.T_world_sensor = ReadOsnabrueckPose(pose);
            } else {
                if (!poses.empty()) throw ReadError(scans[i], "has no .frames or .pose file");
                break;
            }
            poses.push_back(stamped);
        }
    }
    return {DatasetFormat::kOsnabrueck, root, std::move(scans), std::move(poses)};
}

Dataset OpenFolder(const fs::path& root, const DatasetOptions& options) {
    auto scans = ListFolderScans(root);
    const fs::path poses_file = ExistingOr(options.poses_file, root / "poses.txt");
    const fs::path times_file = ExistingOr({}, root / "times.txt");
    if (poses_file.empty()) {
        std::vector<double> times_s = TimesOfScans(scans, times_file, /*by_frame=*/false);
        return {DatasetFormat::kFolder, root, std::move(scans), {}, std::move(times_s)};
    }
    const fs::path calib_file = ExistingOr(options.calib_file, {});
    const core::Transform T_cam0_velo =
        calib_file.empty() ? core::Transform::Identity() : ReadKittiCalibTr(calib_file);
    std::vector<core::StampedPose> poses = ReadPosesFile(poses_file, T_cam0_velo, times_file);
    return {DatasetFormat::kFolder, root, std::move(scans), std::move(poses)};
}

// A bag's scans with the poses of `options.poses_file`: a KITTI file has no times, so its poses
// take the scans' stamps; a TUM file keeps its own.
Dataset OpenBag(const fs::path& bag, const DatasetOptions& options) {
    std::shared_ptr<const BagScans> scans = BagScans::Open(bag, options.topic);
    std::vector<core::StampedPose> poses;
    if (!options.poses_file.empty()) {
        const core::Transform T_cam0_velo = options.calib_file.empty()
                                                ? core::Transform::Identity()
                                                : ReadKittiCalibTr(options.calib_file);
        poses = ReadPosesFile(options.poses_file, T_cam0_velo, {});
        if (poses.size() == scans->size() && !IsTumPosesFile(options.poses_file)) {
            for (std::size_t i = 0; i < poses.size(); ++i) poses[i].time_s = scans->times_s()[i];
        }
    }
    return {std::move(scans), std::move(poses)};
}

// The layout of the scans directly in `root` (not in its subfolders but velodyne/), if any.
std::optional<DatasetFormat> FoundFormat(const fs::path& root) {
    if (!ListFiles(root / "velodyne", IsKittiBin).empty()) return DatasetFormat::kKitti;
    if (!ListFiles(root, IsOsnabrueckScan).empty()) return DatasetFormat::kOsnabrueck;
    if (!ListFolderScans(root).empty()) return DatasetFormat::kFolder;
    return std::nullopt;
}

// A folder of sequences (KITTI's 00/, 08/ ...) is not one: name those that are, to pick from.
// Only a hint: a subfolder that cannot be read is left out, not an error of its own.
std::string SubfolderDatasetsHint(const fs::path& root) try {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(root)) {
        const fs::path& sub = entry.path();
        if (!entry.is_directory() || sub.filename() == "velodyne") continue;
        const std::optional<DatasetFormat> format = FoundFormat(sub);
        // A subfolder of .txt files alone more likely holds poses (KITTI's poses/00.txt).
        if (format && (format != DatasetFormat::kFolder ||
                       ListFolderScans(sub).front().extension() != ".txt")) {
            names.push_back(sub.filename().string());
        }
    }
    if (names.empty()) return {};
    std::sort(names.begin(), names.end(), NaturalLess);
    std::string hint = "; its subfolders ";
    for (std::size_t i = 0; i < names.size(); ++i) hint += (i == 0 ? "" : ", ") + names[i];
    return hint + " hold scans: give one of them";
} catch (const fs::filesystem_error&) {
    return {};
}

DatasetFormat DetectFormat(const fs::path& root) {
    if (const std::optional<DatasetFormat> format = FoundFormat(root)) return *format;
    throw ReadError(root,
                    "cannot tell the dataset format: found no velodyne/*.bin (KITTI), no "
                    "scanNNN.3d (Osnabrueck) and no .pcd/.ply/.xyz/.txt/.pts/.bin scans "
                    "(folder)" +
                        SubfolderDatasetsHint(root));
}

}  // namespace

std::vector<core::StampedPose> PosesOfFrames(const std::vector<fs::path>& scans,
                                             std::vector<core::StampedPose> poses,
                                             const fs::path& poses_file) {
    if (IsTumPosesFile(poses_file)) return poses;
    const std::optional<std::vector<std::size_t>> frames =
        FramesToPick(scans, poses.size(), "poses", poses_file);
    if (!frames) return poses;
    // The path between two frames is the trajectory's, not the straight line between them.
    const std::vector<double> path_m = core::CumulativePathM(poses);
    std::vector<core::StampedPose> selected;
    selected.reserve(frames->size());
    for (const std::size_t frame : *frames) {
        selected.push_back(poses[frame]);
        selected.back().path_m = path_m[frame];
    }
    return selected;
}

std::string FramesNote(const std::vector<fs::path>& scans,
                       const std::vector<core::StampedPose>& poses, const std::string& what) {
    if (!core::KnowsDrivePath(poses) || poses.size() != scans.size()) return {};
    const std::optional<std::vector<std::size_t>> frames = FrameNumbers(scans);
    if (!frames) return {};
    return "the " + std::to_string(scans.size()) + " scans are frames of a KITTI drive (" +
           std::to_string(frames->front()) + " to " + std::to_string(frames->back()) +
           ", by their file names): they take those frames' " + what +
           ", and the path between them is the drive's";
}

std::string PosesOfFramesHint(const std::vector<fs::path>& scans, std::size_t poses) {
    if (scans.empty() || poses <= scans.size()) return {};
    const auto unnamed = std::find_if(scans.begin(), scans.end(), [](const fs::path& scan) {
        return !FrameNumber(scan).has_value();
    });
    if (unnamed != scans.end()) {
        return " (poses are taken by frame number only when every scan is named by one, and " +
               unnamed->filename().string() + " is not)";
    }
    if (FirstFrames(*FrameNumbers(scans))) {
        return " (the scans are frames 0 to " + std::to_string(scans.size() - 1) +
               ": their poses file holds one pose a scan)";
    }
    return " (a TUM file's rows are times, not frames: give a KITTI file of one pose a frame)";
}

Dataset::Dataset(DatasetFormat format, fs::path root, std::vector<fs::path> scan_files,
                 std::vector<core::StampedPose> poses, std::vector<double> times_s)
    : format_(format),
      root_(std::move(root)),
      scan_files_(std::move(scan_files)),
      poses_(std::move(poses)),
      times_s_(std::move(times_s)) {}

Dataset::Dataset(std::shared_ptr<const BagScans> bag, std::vector<core::StampedPose> poses)
    : format_(DatasetFormat::kRosbag), root_(bag->file()), poses_(std::move(poses)) {
    scan_files_.reserve(bag->size());
    for (std::size_t i = 0; i < bag->size(); ++i)
        scan_files_.emplace_back(ToString(BagScanReference{bag->file(), bag->topic(), i}));
    bag_ = std::move(bag);
}

std::string Dataset::FormatName() const {
    switch (format_) {
        case DatasetFormat::kKitti:
            return "kitti";
        case DatasetFormat::kFolder:
            return "folder";
        case DatasetFormat::kOsnabrueck:
            return "osnabrueck";
        case DatasetFormat::kRosbag:
            return "rosbag";
        case DatasetFormat::kAuto:
            break;
    }
    return "auto";
}

const fs::path& Dataset::ScanPath(std::size_t index) const { return scan_files_.at(index); }

core::PointCloud Dataset::LoadScan(std::size_t index) const {
    if (bag_) return bag_->Load(index);
    return ReadScan(ScanPath(index));
}

double Dataset::ScanTime(std::size_t index) const {
    if (bag_) return bag_->times_s().at(index);
    if (HasPoses()) return poses_.at(index).time_s;
    return times_s_.empty() ? static_cast<double>(index) : times_s_.at(index);
}

std::string Dataset::Topic() const { return bag_ ? bag_->topic() : std::string(); }

std::vector<fs::path> Dataset::InputFiles() const {
    std::vector<fs::path> files{root_};
    for (const fs::path& file : given_files_) {
        if (!file.empty()) files.push_back(file);
    }
    return files;
}

namespace {

Dataset OpenDatasetOf(const fs::path& path, const DatasetOptions& options) {
    std::error_code ec;
    if (!fs::exists(path, ec)) {
        throw ReadError(path, IsBagFile(path) ? "no such bag" : "no such dataset folder");
    }
    if (!fs::is_directory(path, ec) && IsBagFile(path)) {
        if (options.format != DatasetFormat::kAuto && options.format != DatasetFormat::kRosbag)
            throw ReadError(path, "is a ROS bag, not a folder of the layout asked for");
        Dataset dataset = OpenBag(path, options);
        if (dataset.HasPoses() && dataset.poses().size() != dataset.size()) {
            throw ReadError(options.poses_file,
                            "has " + std::to_string(dataset.poses().size()) + " poses but " +
                                path.string() + " has " + std::to_string(dataset.size()) +
                                " scans on topic " + core::Quoted(dataset.Topic()));
        }
        return dataset;
    }
    if (!fs::is_directory(path, ec)) {
        throw ReadError(path, "is a file; a dataset is a folder of scans or a ROS bag (.bag)");
    }
    if (!options.topic.empty()) {
        throw ReadError(path, "is a folder; a topic (" + core::Quoted(options.topic) +
                                  ") names the scans of a ROS bag");
    }
    if (options.format == DatasetFormat::kRosbag) throw ReadError(path, "is a folder, not a bag");
    RefuseIncompleteDataset(path);
    const DatasetFormat format =
        options.format == DatasetFormat::kAuto ? DetectFormat(path) : options.format;
    Dataset dataset = format == DatasetFormat::kKitti        ? OpenKitti(path, options)
                      : format == DatasetFormat::kOsnabrueck ? OpenOsnabrueck(path, options)
                                                             : OpenFolder(path, options);
    if (dataset.size() == 0) {
        throw ReadError(path, "holds no scans of the " + dataset.FormatName() + " layout");
    }
    if (dataset.HasPoses() && dataset.poses().size() != dataset.size()) {
        throw ReadError(path,
                        "has " + std::to_string(dataset.size()) + " scans but " +
                            std::to_string(dataset.poses().size()) + " poses" +
                            (format == DatasetFormat::kKitti
                                 ? PosesOfFramesHint(dataset.ScanPaths(), dataset.poses().size())
                                 : std::string()));
    }
    return dataset;
}

}  // namespace

Dataset OpenDataset(const fs::path& path, const DatasetOptions& options) {
    Dataset dataset = OpenDatasetOf(path, options);
    dataset.set_given_files({options.poses_file, options.calib_file});
    return dataset;
}

}  // namespace lidarloop::io

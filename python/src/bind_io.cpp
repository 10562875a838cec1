// Reading scans, poses and datasets (lidarloop.io, docs/python.md).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <string>

#include "bindings.hpp"
#include "conversions.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/io/rosbag.hpp"
#include "lidarloop/io/scan_reader.hpp"

namespace lidarloop::python {
namespace {

using std::filesystem::path;

io::DatasetFormat ParseDatasetFormat(const std::string& name) {
    if (name == "auto") return io::DatasetFormat::kAuto;
    if (name == "kitti") return io::DatasetFormat::kKitti;
    if (name == "folder") return io::DatasetFormat::kFolder;
    if (name == "osnabrueck") return io::DatasetFormat::kOsnabrueck;
    if (name == "rosbag") return io::DatasetFormat::kRosbag;
    throw core::ConfigError("format must be auto | kitti | folder | osnabrueck | rosbag, got '" +
                            name + "'");
}

// Python's index rules: -1 is the last scan; IndexError (which ends a for loop) past the end.
std::size_t ScanIndex(const io::Dataset& dataset, py::ssize_t index) {
    const auto size = static_cast<py::ssize_t>(dataset.size());
    const py::ssize_t from_start = index < 0 ? index + size : index;
    if (from_start < 0 || from_start >= size) {
        throw py::index_error("scan index " + std::to_string(index) + " out of range for " +
                              std::to_string(size) + " scans");
    }
    return static_cast<std::size_t>(from_start);
}

py::array_t<float> ReadScanArray(const path& file) {
    core::PointCloud cloud;
    {
        py::gil_scoped_release release;
        cloud = io::ReadScan(file);
    }
    return PointsToArray(std::move(cloud));
}

py::tuple ReadPosesArrays(const path& file, const py::object& calib, const py::object& times) {
    std::vector<core::StampedPose> poses;
    const path calib_file = calib.is_none() ? path() : calib.cast<path>();
    const path times_file = times.is_none() ? path() : times.cast<path>();
    {
        py::gil_scoped_release release;
        const core::Transform T_cam0_velo =
            calib_file.empty() ? core::Transform::Identity() : io::ReadKittiCalibTr(calib_file);
        poses = io::ReadPoses(file, T_cam0_velo, times_file);
    }
    return PosesToArrays(poses);
}

io::Dataset OpenDatasetAt(const path& folder, const std::string& format, const py::object& poses,
                          const py::object& calib, const py::object& topic) {
    io::DatasetOptions options;
    options.format = ParseDatasetFormat(format);
    if (!poses.is_none()) options.poses_file = poses.cast<path>();
    if (!calib.is_none()) options.calib_file = calib.cast<path>();
    if (!topic.is_none()) options.topic = topic.cast<std::string>();
    py::gil_scoped_release release;
    return io::OpenDataset(folder, options);
}

void BindDataset(py::module_& m) {
    py::class_<io::Dataset>(m, "Dataset",
                            "An ordered sequence of scans with optional ground-truth poses; "
                            "scans are read on demand. Made by open_dataset.")
        .def("__len__", &io::Dataset::size)
        .def(
            "__getitem__",
            [](const io::Dataset& dataset, py::ssize_t index) {
                const std::size_t i = ScanIndex(dataset, index);
                core::PointCloud cloud;
                {
                    py::gil_scoped_release release;
                    cloud = dataset.LoadScan(i);
                }
                return PointsToArray(std::move(cloud));
            },
            py::arg("index"),
            "Scan `index` (negative counts from the end) as an (N, 3) float32 array: sensor "
            "frame, metres. IndexError past the end; lidarloop.ReadError for a bad file or "
            "message.")
        .def_property_readonly("format", &io::Dataset::FormatName,
                               "The layout: 'kitti', 'folder', 'osnabrueck' or 'rosbag'.")
        .def_property_readonly("root", &io::Dataset::root,
                               "The folder it was opened from, or the bag file.")
        .def_property_readonly("topic", &io::Dataset::Topic,
                               "A bag's PointCloud2 topic ('' for a folder).")
        .def_property_readonly(
            "times",
            [](const io::Dataset& dataset) {
                std::vector<double> times(dataset.size());
                for (std::size_t i = 0; i < times.size(); ++i) times[i] = dataset.ScanTime(i);
                return py::array_t<double>(static_cast<py::ssize_t>(times.size()), times.data());
            },
            "(N,) float64 seconds: a bag message's header stamp, else the pose's time, else the "
            "line of times.txt, else the scan index.")
        .def_property_readonly(
            "names",
            [](const io::Dataset& dataset) {
                py::list names;
                for (std::size_t i = 0; i < dataset.size(); ++i) {
                    names.append(dataset.ScanPath(i).string());
                }
                return names;
            },
            "The scan files in scan order (str paths); for a bag, 'BAG:TOPIC:INDEX' references, "
            "which read_scan reads too.")
        .def_property_readonly("has_poses", &io::Dataset::HasPoses)
        .def_property_readonly(
            "poses", [](const io::Dataset& dataset) { return PosesToArrays(dataset.poses()); },
            "(times_s (N,), T_world_sensor (N, 4, 4)) float64 arrays, one pose per scan (empty "
            "arrays when the dataset has none). Time in seconds, world frame in metres.")
        .def_property_readonly(
            "path_m",
            [](const io::Dataset& dataset) -> std::optional<std::vector<double>> {
                if (!dataset.HasPoses()) return std::nullopt;
                return core::CumulativePathM(dataset.poses());
            },
            "Per scan, metres travelled from the first scan (None without poses): the straight "
            "steps between the poses, or for some frames of a KITTI drive the drive's own path. "
            "Pass it as build_ground_truth's path_m.")
        .def("__repr__", [](const io::Dataset& dataset) {
            return "<lidarloop.Dataset " + dataset.FormatName() + " " + dataset.root().string() +
                   ": " + std::to_string(dataset.size()) + " scans>";
        });
}

}  // namespace

void BindIo(py::module_& m) {
    m.def("read_scan", &ReadScanArray, py::arg("file"),
          "Reads one scan file (.bin KITTI, .pcd, .ply, .xyz, .txt, .pts, .3d Osnabrueck), or "
          "a message of a ROS 1 bag named 'BAG:TOPIC:INDEX', into "
          "an (N, 3) float32 array: sensor frame, metres, x forward, z up. The array owns the "
          "C++ reader's memory (no copy); intensity and other fields are dropped, non-finite "
          "points kept. lidarloop.ReadError (.file) for a missing, unknown or damaged file.");
    m.def("is_scan_file", &io::IsScanFile, py::arg("file"),
          "Whether read_scan knows the file's extension.");
    m.def("reads_bags", &io::RosbagSupported,
          "Whether this lidarloop was built with ROS 1 bag support (LIDARLOOP_WITH_ROSBAG).");
    m.def("read_poses", &ReadPosesArrays, py::arg("file"), py::arg("calib") = py::none(),
          py::arg("times") = py::none(),
          "Reads a KITTI poses.txt (12 numbers a line) or TUM trajectory (8 numbers a line) "
          "into (times_s (N,), T_world_sensor (N, 4, 4)) float64 arrays. With `calib` (KITTI "
          "calib.txt) KITTI camera poses become LiDAR poses; `times` (KITTI times.txt) gives "
          "their times, else the line index. lidarloop.ReadError naming the bad line.");
    m.def("open_dataset", &OpenDatasetAt, py::arg("folder"), py::arg("format") = "auto",
          py::arg("poses") = py::none(), py::arg("calib") = py::none(),
          py::arg("topic") = py::none(),
          "Opens a folder of scans: 'kitti' (velodyne/*.bin, poses.txt, calib.txt), 'folder' "
          "(scan files in natural name order) or 'osnabrueck' (scanNNN.3d); 'auto' detects it. "
          "Or a ROS 1 bag (a .bag file, 'rosbag'): the sensor_msgs/PointCloud2 messages of "
          "`topic` (default: the bag's only PointCloud2 topic), stamped by their headers. "
          "`poses` (KITTI or TUM file) and `calib` override the files beside the scans. "
          "lidarloop.ReadError when the folder holds no scans, poses do not match them, or the "
          "bag or topic cannot be read (naming the file and the topic).");
    BindDataset(m);
}

}  // namespace lidarloop::python

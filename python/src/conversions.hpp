#pragma once

// Conversions between NumPy arrays and lidarloop's C++ types, shared by every bind_<area>.cpp.
// They raise the Python layer's errors (errors.hpp) for arrays lidarloop cannot take, and must
// run with the GIL held (they read Python objects); release it afterwards for the long work.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>

#include "errors.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::python {

namespace py = pybind11;

/// Whether `object` is a NumPy array of exactly dtype T in native byte order.
template <typename T>
bool IsArrayOf(const py::handle& object) {
    return py::isinstance<py::array_t<T>>(object);
}

/// DtypeError unless `object` is a float32 or float64 NumPy array; `what` names the argument.
inline void CheckFloatArray(const py::handle& object, const std::string& what) {
    if (IsArrayOf<float>(object) || IsArrayOf<double>(object)) return;
    const std::string got =
        py::isinstance<py::array>(object)
            ? "an array of dtype " + py::str(object.attr("dtype")).cast<std::string>()
            : "a " + py::str(py::type::of(object).attr("__name__")).cast<std::string>();
    throw DtypeError(what + " must be a NumPy array of float32 or float64, got " + got);
}

/// NonFiniteError for points row `row`.
[[noreturn]] inline void ThrowNonFiniteRow(std::size_t row) {
    throw NonFiniteError("points row " + std::to_string(row) +
                         " is not finite (NaN or infinite); drop such rows, or pass "
                         "skip_non_finite=True to have lidarloop skip and count them");
}

/// The first row of `points` with a NaN or infinite coordinate, if any.
inline std::optional<std::size_t> FirstNonFiniteRow(core::PointsView points) {
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (!points[i].allFinite()) return i;
    }
    return std::nullopt;
}

/// ShapeError unless `points` (a float array) has shape (N, 3) or (N, 4).
inline void CheckPointsShape(const py::array& points) {
    if (points.ndim() != 2 || (points.shape(1) != 3 && points.shape(1) != 4)) {
        throw ShapeError("points must have shape (N, 3) or (N, 4), got " +
                         py::str(points.attr("shape")).cast<std::string>());
    }
}

/// The points of `points` without a copy when their memory is already core::PointsView's
/// layout: a C-contiguous (N, 3) float32 array. The array must outlive the view (and not change
/// while C++ reads it).
inline std::optional<core::PointsView> ViewOfPoints(const py::handle& points) {
    if (!IsArrayOf<float>(points)) return std::nullopt;
    const auto array = py::reinterpret_borrow<py::array_t<float>>(points);
    constexpr auto kRow = static_cast<py::ssize_t>(3 * sizeof(float));
    const bool packed = array.ndim() == 2 && array.shape(1) == 3 &&
                        (array.shape(0) <= 1 || array.strides(0) == kRow) &&
                        array.strides(1) == static_cast<py::ssize_t>(sizeof(float));
    if (!packed) return std::nullopt;
    static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
    return core::PointsView(reinterpret_cast<const Eigen::Vector3f*>(array.data()),
                            static_cast<std::size_t>(array.shape(0)));
}

namespace detail {

template <typename T>
void CopyPoints(const py::array_t<T>& array, bool allow_non_finite, core::PointCloud& cloud) {
    const auto view = array.template unchecked<2>();  // follows the strides: any layout
    cloud.resize(static_cast<std::size_t>(view.shape(0)));
    for (py::ssize_t i = 0; i < view.shape(0); ++i) {
        Eigen::Vector3f& point = cloud[static_cast<std::size_t>(i)];
        point = {static_cast<float>(view(i, 0)), static_cast<float>(view(i, 1)),
                 static_cast<float>(view(i, 2))};
        if (!allow_non_finite && !point.allFinite()) ThrowNonFiniteRow(static_cast<std::size_t>(i));
    }
}

}  // namespace detail

/// Copies points in the sensor frame, metres, from an (N, 3) or (N, 4) float32 or float64 array in
/// any memory layout (the 4th column, e.g. intensity, is ignored). core::PointCloud is a
/// std::vector of Eigen::Vector3f, which cannot borrow NumPy's memory, so this is one copy
/// (12 bytes a point; float64 is rounded to float32, as the readers of files do). DtypeError,
/// ShapeError, and NonFiniteError for a NaN or infinite coordinate unless `allow_non_finite`
/// (then the C++ side skips and counts them, as it does for files).
inline void CopyPointsInto(const py::handle& points, bool allow_non_finite,
                           core::PointCloud& cloud) {
    CheckFloatArray(points, "points");
    CheckPointsShape(py::reinterpret_borrow<py::array>(points));
    if (IsArrayOf<float>(points)) {
        detail::CopyPoints(py::reinterpret_borrow<py::array_t<float>>(points), allow_non_finite,
                           cloud);
    } else {
        detail::CopyPoints(py::reinterpret_borrow<py::array_t<double>>(points), allow_non_finite,
                           cloud);
    }
}

inline core::PointCloud PointsFromArray(const py::handle& points, bool allow_non_finite) {
    core::PointCloud cloud;
    CopyPointsInto(points, allow_non_finite, cloud);
    return cloud;
}

/// PointsFromArray into a buffer of the calling thread, kept between calls, for calls that
/// read the points only while they run: a fresh buffer for a large scan is mapped anew by malloc
/// each time, and its page faults cost more than the copy. Valid until the thread's next call.
inline const core::PointCloud& ScratchPointsFromArray(const py::handle& points,
                                                      bool allow_non_finite) {
    thread_local core::PointCloud scratch;
    CopyPointsInto(points, allow_non_finite, scratch);
    return scratch;
}

/// An (N, 3) float32 array that owns `cloud` and views its memory: no copy (Eigen::Vector3f is
/// three packed floats).
inline py::array_t<float> PointsToArray(core::PointCloud cloud) {
    auto owner = std::make_unique<core::PointCloud>(std::move(cloud));
    const auto rows = static_cast<py::ssize_t>(owner->size());
    float* data = owner->empty() ? nullptr : owner->front().data();
    py::capsule base(owner.get(), [](void* p) { delete static_cast<core::PointCloud*>(p); });
    owner.release();
    constexpr auto kFloat = static_cast<py::ssize_t>(sizeof(float));
    return py::array_t<float>({rows, py::ssize_t{3}}, {3 * kFloat, kFloat}, data, base);
}

/// A 1-D float64 array viewing `values` (no copy), kept alive by `owner`, the Python object
/// that holds them. Read-only, so that Python cannot change what C++ holds.
inline py::array_t<double> ViewOf(const std::vector<double>& values, const py::handle& owner) {
    py::array_t<double> array({static_cast<py::ssize_t>(values.size())}, {sizeof(double)},
                              values.data(), owner);
    array.attr("setflags")(py::arg("write") = false);
    return array;
}

/// A 1-D array of `values` (a copy), of any arithmetic type.
template <typename T>
py::array_t<T> ArrayOf(const std::vector<T>& values) {
    py::array_t<T> array(static_cast<py::ssize_t>(values.size()));
    std::copy(values.begin(), values.end(), array.mutable_data());
    return array;
}

/// `scan` when `scans` (anything with a size(): a database, a ground truth) has it; IndexError
/// otherwise, for C++ calls that index unchecked.
template <typename Scans>
std::size_t CheckedScan(const Scans& scans, std::size_t scan) {
    if (scan >= scans.size()) {
        throw py::index_error("scan " + std::to_string(scan) + " out of range for " +
                              std::to_string(scans.size()) + " scans");
    }
    return scan;
}

/// A copy of `matrix` as a float64 array of its shape.
template <typename Derived>
py::array_t<double> MatrixToArray(const Eigen::MatrixBase<Derived>& matrix) {
    py::array_t<double> array(
        {static_cast<py::ssize_t>(matrix.rows()), static_cast<py::ssize_t>(matrix.cols())});
    auto out = array.mutable_unchecked<2>();
    for (Eigen::Index r = 0; r < matrix.rows(); ++r) {
        for (Eigen::Index c = 0; c < matrix.cols(); ++c) out(r, c) = matrix(r, c);
    }
    return array;
}

/// A 4x4 float64 array of `T` (a T_target_source).
inline py::array_t<double> TransformToArray(const core::Transform& T) {
    return MatrixToArray(T.matrix());
}

/// A rigid transform T_target_source from a 4x4 float32/float64 array: DtypeError, ShapeError,
/// NonFiniteError, and ShapeError when the last row is not (0, 0, 0, 1) (within 1e-9). The
/// rotation part is taken as given. `what` names the argument in messages.
inline core::Transform TransformFromArray(const py::handle& object, const std::string& what) {
    CheckFloatArray(object, what);
    const auto array = py::array_t<double, py::array::forcecast>::ensure(object);
    if (array.ndim() != 2 || array.shape(0) != 4 || array.shape(1) != 4) {
        throw ShapeError(what + " must have shape (4, 4), got " +
                         py::str(object.attr("shape")).cast<std::string>());
    }
    const auto view = array.unchecked<2>();
    core::Transform T = core::Transform::Identity();
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) {
            if (!std::isfinite(view(r, c))) throw NonFiniteError(what + " is not finite");
            if (r < 3) T.matrix()(r, c) = view(r, c);
        }
    }
    const bool last_row = std::abs(view(3, 0)) < 1e-9 && std::abs(view(3, 1)) < 1e-9 &&
                          std::abs(view(3, 2)) < 1e-9 && std::abs(view(3, 3) - 1.0) < 1e-9;
    if (!last_row) throw ShapeError(what + ": the last row of a rigid transform is 0 0 0 1");
    return T;
}

/// Poses as (times_s (N,), T_world_sensor (N, 4, 4)) float64 arrays (copies).
inline py::tuple PosesToArrays(const std::vector<core::StampedPose>& poses) {
    const auto n = static_cast<py::ssize_t>(poses.size());
    py::array_t<double> times(n);
    py::array_t<double> transforms({n, py::ssize_t{4}, py::ssize_t{4}});
    auto t = times.mutable_unchecked<1>();
    auto T = transforms.mutable_unchecked<3>();
    for (py::ssize_t i = 0; i < n; ++i) {
        const core::StampedPose& pose = poses[static_cast<std::size_t>(i)];
        t(i) = pose.time_s;
        for (int r = 0; r < 4; ++r) {
            for (int c = 0; c < 4; ++c) T(i, r, c) = pose.T_world_sensor.matrix()(r, c);
        }
    }
    return py::make_tuple(times, transforms);
}

/// Poses from times_s (N,) and T_world_sensor (N, 4, 4) arrays (float32 or float64); the
/// errors of TransformFromArray, and ShapeError when the counts differ.
inline std::vector<core::StampedPose> PosesFromArrays(const py::handle& times_s,
                                                      const py::handle& T_world_sensor) {
    CheckFloatArray(times_s, "times_s");
    CheckFloatArray(T_world_sensor, "T_world_sensor");
    const auto times = py::array_t<double, py::array::forcecast>::ensure(times_s);
    const auto transforms = py::array_t<double, py::array::forcecast>::ensure(T_world_sensor);
    if (times.ndim() != 1 || transforms.ndim() != 3 || transforms.shape(0) != times.shape(0)) {
        throw ShapeError("poses need times_s of shape (N,) and T_world_sensor of shape (N, 4, 4)");
    }
    std::vector<core::StampedPose> poses(static_cast<std::size_t>(times.shape(0)));
    for (py::ssize_t i = 0; i < times.shape(0); ++i) {
        core::StampedPose& pose = poses[static_cast<std::size_t>(i)];
        pose.time_s = times.at(i);
        if (!std::isfinite(pose.time_s)) throw NonFiniteError("times_s is not finite");
        pose.T_world_sensor = TransformFromArray(transforms[py::make_tuple(i)],
                                                 "T_world_sensor[" + std::to_string(i) + "]");
    }
    return poses;
}

/// Sets each pose's StampedPose::path_m from `path_m` (one per pose): the drive's path for
/// frames of a longer one. ValueError on another count.
inline void SetPathM(const std::vector<double>& path_m, std::vector<core::StampedPose>& poses) {
    if (path_m.size() != poses.size()) {
        throw py::value_error("path_m has " + std::to_string(path_m.size()) + " values for " +
                              std::to_string(poses.size()) + " poses");
    }
    core::CheckPathM(path_m, "path_m");
    for (std::size_t i = 0; i < poses.size(); ++i) poses[i].path_m = path_m[i];
}

/// The run configuration a Python argument names: None gives the defaults; a dict (nested like
/// the YAML file, e.g. {"method": "ndt", "ndt": {"cell_size_m": 1.0}}) or a path (str or
/// os.PathLike) of a YAML file overrides the keys it names. lidarloop.ReadError for unknown keys
/// and invalid values, naming them (io::ApplyConfigYaml).
inline io::RunConfig RunConfigFrom(const py::object& config) {
    io::RunConfig run;
    if (config.is_none()) return run;
    if (py::isinstance<py::dict>(config)) {
        // JSON is YAML: the dict goes through the same parser as a config file. A NumPy scalar
        // (np.float32(1.0), np.int64(50)) is written as the Python number it holds.
        const py::object numpy_scalar = py::module_::import("numpy").attr("generic");
        const py::cpp_function as_number([numpy_scalar](const py::object& value) -> py::object {
            if (py::isinstance(value, numpy_scalar)) return value.attr("item")();
            throw py::type_error("config: " + py::repr(value).cast<std::string>() +
                                 " is no number, name, bool or list");
        });
        const std::string text = py::module_::import("json")
                                     .attr("dumps")(config, py::arg("default") = as_number)
                                     .cast<std::string>();
        io::ApplyConfigYaml(text, "config dict", run);
        return run;
    }
    const std::string path = py::module_::import("os").attr("fspath")(config).cast<std::string>();
    // The file calls would read the path up to the NUL: another file than the one named.
    if (path.find('\0') != std::string::npos)
        throw io::ReadError(path.substr(0, path.find('\0')), "the path holds a NUL character");
    return io::LoadConfigYaml(path, run);
}

/// `value` (a str or os.PathLike, checked by the caller) as a path; ValueError naming `name`
/// where pybind11 cannot convert it, as Python's own open() refuses an embedded null byte,
/// rather than pybind11's bare "Unable to cast".
inline std::filesystem::path PathOf(const py::object& value, const char* name) {
    try {
        return value.cast<std::filesystem::path>();
    } catch (const py::cast_error&) {
        // Looked for on the Python side: a str this system cannot encode would fail to convert
        // to C++ again.
        const py::object text = py::module_::import("os").attr("fspath")(value);
        const py::object null_byte = py::isinstance<py::str>(text)
                                         ? py::object(py::str(std::string(1, '\0')))
                                         : py::object(py::bytes(std::string(1, '\0')));
        const bool has_null = text.attr("__contains__")(null_byte).cast<bool>();
        throw py::value_error(std::string(name) + ": " +
                              (has_null ? "embedded null byte in the path"
                                        : "not a path this system can encode: " +
                                              py::repr(value).cast<std::string>()));
    }
}

}  // namespace lidarloop::python

#include "lidarloop/io/poses.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/text_parsing.hpp"

namespace lidarloop::io {
namespace {

using Fields = std::vector<std::string_view>;

std::string Short(double value) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.3g", value);
    return text;
}

// Text files hold no control characters but tabs; one means binary input, which would otherwise
// be quoted as garbage in a "not a number" message.
void RejectControlCharacters(const detail::LineReader& reader, std::string_view line) {
    const auto bad = std::find_if(line.begin(), line.end(), [](char c) {
        const auto code = static_cast<unsigned char>(c);
        return (code < 0x20 && c != '\t') || code == 0x7f;
    });
    if (bad == line.end()) return;
    char code[8];
    std::snprintf(code, sizeof(code), "0x%02x", static_cast<unsigned char>(*bad));
    reader.Fail(std::string("holds control character ") + code +
                " (binary data?); not a text pose file");
}

// Next line that is neither blank nor a '#' comment; `fields` view into `line`.
bool NextDataLine(detail::LineReader& reader, std::string& line, Fields& fields) {
    while (reader.Next(line)) {
        RejectControlCharacters(reader, line);
        fields = detail::SplitFields(line);
        if (!fields.empty() && !fields.front().starts_with('#')) return true;
    }
    return false;
}

// Points may be NaN, poses may not: a non-finite pose value is an error.
void ParseFiniteNumbers(const detail::LineReader& reader, const Fields& fields, std::size_t count,
                        double* out) {
    reader.ParseNumbers(fields, count, out);
    for (std::size_t i = 0; i < count; ++i) {
        if (!std::isfinite(out[i])) {
            reader.Fail("'" + std::string(fields[i]) + "' is not a finite number");
        }
    }
}

// KITTI prints rotations with ~7 digits: accept small deviations and snap to the nearest rotation
// (so that inverses by transposition stay exact), reject what is no rotation (scaled, garbage).
Eigen::Matrix3d NearestRotationOrFail(const detail::LineReader& reader, const Eigen::Matrix3d& m) {
    const double error = (m.transpose() * m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (error > 1e-3 || m.determinant() <= 0.0) {
        reader.Fail("the 3x3 part is not a rotation (max |R^T R - I| = " + Short(error) +
                    ", det = " + Short(m.determinant()) + ")");
    }
    return Eigen::Quaterniond(m).normalized().toRotationMatrix();
}

// [R | t] from exactly 12 numbers, row-major, starting at fields[first].
core::Transform ParseMatrix3x4(const detail::LineReader& reader, const Fields& fields,
                               std::size_t first) {
    const Fields numbers(fields.begin() + static_cast<std::ptrdiff_t>(first), fields.end());
    if (numbers.size() != 12) {
        reader.Fail("expected 12 numbers (3x4 row-major matrix), got " +
                    std::to_string(numbers.size()));
    }
    double values[12];
    ParseFiniteNumbers(reader, numbers, 12, values);
    const Eigen::Map<const Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> M(values);
    core::Transform T = core::Transform::Identity();
    T.linear() = NearestRotationOrFail(reader, M.leftCols<3>());
    T.translation() = M.col(3);
    return T;
}

std::vector<double> ReadTimes(const std::filesystem::path& times_file) {
    detail::LineReader reader(times_file);
    std::vector<double> times;
    std::string line;
    Fields fields;
    while (NextDataLine(reader, line, fields)) {
        if (fields.size() != 1) {
            reader.Fail("expected 1 number (time in s), got " + std::to_string(fields.size()));
        }
        double time_s = 0.0;
        ParseFiniteNumbers(reader, fields, 1, &time_s);
        times.push_back(time_s);
    }
    return times;
}

void AppendNumber(std::string& text, double value, char separator) {
    char number[32];
    const auto end = std::to_chars(number, number + sizeof(number), value).ptr;
    text.append(number, end);
    text.push_back(separator);
}

void WriteText(const std::filesystem::path& file, const std::string& text) {
    std::ofstream out = detail::OpenForWriting(file, /*binary=*/false);
    out << text;
    out.close();
    if (!out) throw WriteError(file, "writing failed");
}

}  // namespace

core::Transform ReadKittiCalibTr(const std::filesystem::path& calib_file) {
    detail::LineReader reader(calib_file);
    std::string line;
    Fields fields;
    while (NextDataLine(reader, line, fields)) {
        if (fields.front() == "Tr:") return ParseMatrix3x4(reader, fields, 1);
    }
    throw ReadError(calib_file,
                    "has no 'Tr:' line (velodyne to camera 0, 12 numbers); is it a KITTI odometry "
                    "calib.txt?");
}

std::vector<core::StampedPose> ReadKittiPoses(const std::filesystem::path& poses_file,
                                              const core::Transform& T_cam0_velo,
                                              const std::filesystem::path& times_file) {
    detail::LineReader reader(poses_file);
    const core::Transform T_velo_cam0 = T_cam0_velo.inverse();
    std::vector<core::StampedPose> poses;
    std::string line;
    Fields fields;
    while (NextDataLine(reader, line, fields)) {
        core::StampedPose pose;
        pose.time_s = static_cast<double>(poses.size());
        // P_i = T_cam0first_cam0i; conjugating by the calibration gives T_velo0_veloi.
        pose.T_world_sensor = T_velo_cam0 * ParseMatrix3x4(reader, fields, 0) * T_cam0_velo;
        poses.push_back(pose);
    }
    if (times_file.empty()) return poses;
    const std::vector<double> times = ReadTimes(times_file);
    if (times.size() != poses.size()) {
        throw ReadError(times_file, "holds " + std::to_string(times.size()) + " times but " +
                                        poses_file.string() + " holds " +
                                        std::to_string(poses.size()) + " poses");
    }
    for (std::size_t i = 0; i < poses.size(); ++i) poses[i].time_s = times[i];
    return poses;
}

void WriteKittiPoses(const std::filesystem::path& poses_file,
                     const std::vector<core::StampedPose>& poses) {
    std::string text;
    for (const auto& pose : poses) {
        const Eigen::Matrix<double, 3, 4> M = pose.T_world_sensor.matrix().topRows<3>();
        for (int row = 0; row < 3; ++row) {
            for (int col = 0; col < 4; ++col) {
                AppendNumber(text, M(row, col), row == 2 && col == 3 ? '\n' : ' ');
            }
        }
    }
    WriteText(poses_file, text);
}

std::vector<core::StampedPose> ReadTumPoses(const std::filesystem::path& file) {
    detail::LineReader reader(file);
    std::vector<core::StampedPose> poses;
    std::string line;
    Fields fields;
    while (NextDataLine(reader, line, fields)) {
        if (fields.size() != 8) {
            reader.Fail("expected 8 numbers (timestamp tx ty tz qx qy qz qw), got " +
                        std::to_string(fields.size()));
        }
        double v[8];
        ParseFiniteNumbers(reader, fields, 8, v);
        const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);  // Eigen takes w first
        if (q.norm() < 0.9 || q.norm() > 1.1) {
            reader.Fail("quaternion (qx qy qz qw) has norm " + Short(q.norm()) + ", expected 1");
        }
        core::StampedPose pose;
        pose.time_s = v[0];
        pose.T_world_sensor.linear() = q.normalized().toRotationMatrix();
        pose.T_world_sensor.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
        poses.push_back(pose);
    }
    return poses;
}

void WriteTumPoses(const std::filesystem::path& file, const std::vector<core::StampedPose>& poses) {
    std::string text;
    for (const auto& pose : poses) {
        const Eigen::Vector3d t = pose.T_world_sensor.translation();
        const Eigen::Quaterniond q(pose.T_world_sensor.linear());
        for (const double value : {pose.time_s, t.x(), t.y(), t.z(), q.x(), q.y(), q.z()}) {
            AppendNumber(text, value, ' ');
        }
        AppendNumber(text, q.w(), '\n');
    }
    WriteText(file, text);
}

}  // namespace lidarloop::io

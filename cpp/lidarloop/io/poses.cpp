#include "lidarloop/io/poses.hpp"

#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "lidarloop/io/detail/rotation_check.hpp"
#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {
namespace {

using Fields = std::vector<std::string_view>;

// Farther from the origin than any Earth-fixed frame puts a sensor (UTM northings reach 1e7 m,
// ECEF coordinates 6.4e6 m): a corrupt value, which would otherwise make the ATE 1e28 m.
constexpr double kMaxPositionM = 1e8;

// Next line that is neither blank nor a '#' comment; `fields` view into `line`.
bool NextDataLine(detail::LineReader& reader, std::string& line, Fields& fields) {
    while (reader.Next(line)) {
        detail::RejectControlCharacters(reader, line, "text pose file");
        fields = detail::SplitFields(line);
        if (!fields.empty() && !fields.front().starts_with('#')) return true;
    }
    return false;
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
    reader.ParseFiniteNumbers(numbers, 12, values);
    const Eigen::Map<const Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> M(values);
    core::Transform T = core::Transform::Identity();
    T.linear() = detail::NearestRotationOrFail(reader, M.leftCols<3>());
    T.translation() = M.col(3);
    return T;
}

// Fails naming the current line when `pose` is implausible: farther than kMaxPositionM from the
// origin, more than max_step_m from `previous` (nullptr for the first pose).
void CheckPosition(const detail::LineReader& reader, const core::Transform& pose,
                   const core::Transform* previous, double max_step_m) {
    const double distance_m = pose.translation().stableNorm();  // 1e200 squared overflows
    if (distance_m > kMaxPositionM) {
        reader.Fail("the position is " + detail::ShortNumber(distance_m) +
                    " m from the origin (more than " + detail::ShortNumber(kMaxPositionM) +
                    " m: a corrupt value?)");
    }
    if (previous == nullptr) return;
    const double step_m = (pose.translation() - previous->translation()).norm();
    if (step_m > max_step_m) {
        reader.Fail("the pose is " + detail::ShortNumber(step_m) +
                    " m from the one before (at most " + detail::ShortNumber(max_step_m) +
                    " m between consecutive scans: does the odometry jump or reset?)");
    }
}

// Fails naming the current line unless `time_s` comes after `previous_s`.
void CheckTimeIncreases(const detail::LineReader& reader, double time_s, double previous_s) {
    if (time_s > previous_s) return;
    reader.Fail("time " + detail::ShortNumber(time_s) +
                (time_s == previous_s
                     ? " repeats the time before"
                     : " goes back from the time before, " + detail::ShortNumber(previous_s)) +
                " (times must increase)");
}

}  // namespace

std::vector<double> ReadKittiTimes(const std::filesystem::path& times_file) {
    detail::LineReader reader(times_file);
    std::vector<double> times;
    std::string line;
    Fields fields;
    while (NextDataLine(reader, line, fields)) {
        if (fields.size() != 1) {
            reader.Fail("expected 1 number (time in s), got " + std::to_string(fields.size()));
        }
        double time_s = 0.0;
        reader.ParseFiniteNumbers(fields, 1, &time_s);
        if (!times.empty()) CheckTimeIncreases(reader, time_s, times.back());
        times.push_back(time_s);
    }
    return times;
}

core::Transform ReadKittiCalibTr(const std::filesystem::path& calib_file) {
    detail::LineReader reader(calib_file);
    std::string line;
    Fields fields;
    std::optional<core::Transform> Tr;
    std::size_t Tr_line = 0;
    while (NextDataLine(reader, line, fields)) {
        if (fields.front() != "Tr:") continue;
        // Two calibrations in one file: which is meant cannot be told.
        if (Tr)
            reader.Fail("a second 'Tr:' line (the first is line " + std::to_string(Tr_line) + ")");
        Tr = ParseMatrix3x4(reader, fields, 1);
        Tr_line = reader.line_number();
    }
    if (Tr) return *Tr;
    throw ReadError(calib_file,
                    "has no 'Tr:' line (velodyne to camera 0, 12 numbers); is it a KITTI odometry "
                    "calib.txt?");
}

namespace {

// ReadKittiPoses with a bound on the step between consecutive poses (ReadPoses).
std::vector<core::StampedPose> ReadKittiPosesBounded(const std::filesystem::path& poses_file,
                                                     const core::Transform& T_cam0_velo,
                                                     const std::filesystem::path& times_file,
                                                     double max_step_m) {
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
        CheckPosition(reader, pose.T_world_sensor,
                      poses.empty() ? nullptr : &poses.back().T_world_sensor, max_step_m);
        poses.push_back(pose);
    }
    if (times_file.empty()) return poses;
    const std::vector<double> times = ReadKittiTimes(times_file);
    if (times.size() != poses.size()) {
        throw ReadError(times_file, "holds " + std::to_string(times.size()) + " times but " +
                                        poses_file.string() + " holds " +
                                        std::to_string(poses.size()) + " poses");
    }
    for (std::size_t i = 0; i < poses.size(); ++i) poses[i].time_s = times[i];
    return poses;
}

// ReadTumPoses with a bound on the step between consecutive poses (ReadPoses).
std::vector<core::StampedPose> ReadTumPosesBounded(const std::filesystem::path& file,
                                                   double max_step_m);

}  // namespace

std::vector<core::StampedPose> ReadKittiPoses(const std::filesystem::path& poses_file,
                                              const core::Transform& T_cam0_velo,
                                              const std::filesystem::path& times_file) {
    return ReadKittiPosesBounded(poses_file, T_cam0_velo, times_file,
                                 std::numeric_limits<double>::infinity());
}

void WriteKittiPoses(const std::filesystem::path& poses_file,
                     const std::vector<core::StampedPose>& poses) {
    std::string text;
    for (const auto& pose : poses) {
        const Eigen::Matrix<double, 3, 4> M = pose.T_world_sensor.matrix().topRows<3>();
        for (int row = 0; row < 3; ++row) {
            for (int col = 0; col < 4; ++col) {
                detail::AppendNumber(text, M(row, col), row == 2 && col == 3 ? '\n' : ' ');
            }
        }
    }
    detail::WriteTextFile(poses_file, text);
}

namespace {

std::vector<core::StampedPose> ReadTumPosesBounded(const std::filesystem::path& file,
                                                   double max_step_m) {
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
        reader.ParseFiniteNumbers(fields, 8, v);
        const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);  // Eigen takes w first
        if (q.norm() < 0.9 || q.norm() > 1.1) {
            reader.Fail("quaternion (qx qy qz qw) has norm " + detail::ShortNumber(q.norm()) +
                        ", expected 1");
        }
        core::StampedPose pose;
        pose.time_s = v[0];
        pose.T_world_sensor.linear() = q.normalized().toRotationMatrix();
        pose.T_world_sensor.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
        const core::StampedPose* previous = poses.empty() ? nullptr : &poses.back();
        if (previous != nullptr) CheckTimeIncreases(reader, pose.time_s, previous->time_s);
        CheckPosition(reader, pose.T_world_sensor,
                      previous != nullptr ? &previous->T_world_sensor : nullptr, max_step_m);
        poses.push_back(pose);
    }
    return poses;
}

}  // namespace

std::vector<core::StampedPose> ReadTumPoses(const std::filesystem::path& file) {
    return ReadTumPosesBounded(file, std::numeric_limits<double>::infinity());
}

bool IsTumPosesFile(const std::filesystem::path& file) {
    detail::LineReader reader(file);
    std::string line;
    Fields fields;
    return NextDataLine(reader, line, fields) && fields.size() == 8;
}

std::vector<core::StampedPose> ReadPoses(const std::filesystem::path& file,
                                         const core::Transform& T_cam0_velo,
                                         const std::filesystem::path& times_file,
                                         double max_step_m) {
    detail::LineReader reader(file);
    std::string line;
    Fields fields;
    if (!NextDataLine(reader, line, fields)) return {};
    if (fields.size() == 12) {
        return ReadKittiPosesBounded(file, T_cam0_velo, times_file, max_step_m);
    }
    if (fields.size() == 8) return ReadTumPosesBounded(file, max_step_m);
    reader.Fail("cannot tell the pose format: expected 12 numbers (KITTI) or 8 (TUM), got " +
                std::to_string(fields.size()));
}

void WriteTumPoses(const std::filesystem::path& file, const std::vector<core::StampedPose>& poses) {
    std::string text;
    for (const auto& pose : poses) {
        const Eigen::Vector3d t = pose.T_world_sensor.translation();
        const Eigen::Quaterniond q(pose.T_world_sensor.linear());
        for (const double value : {pose.time_s, t.x(), t.y(), t.z(), q.x(), q.y(), q.z()}) {
            detail::AppendNumber(text, value, ' ');
        }
        detail::AppendNumber(text, q.w(), '\n');
    }
    detail::WriteTextFile(file, text);
}

}  // namespace lidarloop::io

// Osnabrück Robotic 3D Scan Repository files, as read and written by 3DTK (slam6D).
//
// The 3DTK conventions, from reading the 3DTK/3DTK sources (include/slam6d/globals.icc,
// src/scanio/helper.cc, src/scanio/framesreader.cc):
// - 4x4 matrices are double[16] in OpenGL column-major order: transform3() computes
//   x' = M[0] x + M[4] y + M[8] z + M[12], so element (row r, column c) is M[4 c + r] and the
//   translation is M[12..14]. A matrix maps scan-local points to world points: p_w = R p + t.
// - A .pose file holds six numbers read with operator>> (so line breaks do not matter):
//   rPos = x y z in cm, then rPosTheta = rx ry rz in degrees, converted with rad() on reading
//   (readPoseHelper in helper.cc).
// - EulerToMatrix4(rPos, rPosTheta) writes the column-major elements
//   [cy cz, sx sy cz + cx sz, -cx sy cz + sx sz, 0, -cy sz, ...]. Multiplying out
//   Rx(rx) * Ry(ry) * Rz(rz) with the usual right-hand-rule matrices gives exactly these nine
//   elements, so R = Rx(rx) Ry(ry) Rz(rz) (rotate about z first, then y, then x, all about the
//   fixed axes), and Matrix4ToEuler inverts it with ry = asin(M[8]) = asin(R(0, 2)).
// - A .frames file holds one line per registration step: the 16 column-major values of the
//   scan's absolute pose matrix (operator<< for double[16]) and an algorithm/colour code; 3DTK
//   reads all lines and keeps the last (framesreader.cc; readPoseHelper reads 17 numbers from the
//   last line). It is the same kind of pose as the .pose file: p_w = R p + t, cm.
// - Point files (scan_io_uos) are text x y z lines; uosHeaderTest skips a first line "W x H".
//   ScanDataTransform_xyz converts right-handed x-forward/z-up metres to 3DTK as
//   x_3dtk = -100 y, y_3dtk = 100 z, z_3dtk = 100 x, which is the inverse of our
//   FromOsnabrueckCoordinates.
// Verification here: tests/cpp/io/test_osnabrueck.cpp builds R from the element formulas above
// (not from this file's code) and checks, for random poses, that transforming a point in 3DTK
// coordinates and then converting equals converting first and applying the converted pose; and a
// hand-worked case: ry = +90 degrees (about 3DTK's up axis y) is a right turn, yaw -90 degrees
// here, since the left-handed frame reverses the sense of rotations.
//
// Conversion of a pose: with the linear map C (x_ll = z, y_ll = -x, z_ll = y; det C = -1),
// p_ll = C p_3dtk / 100, so p_w = R p + t becomes p_w,ll = (C R C^-1) p_ll + C t / 100. C R C^-1
// is a proper rotation (det +1) because C appears on both sides.

#include "lidarloop/io/osnabrueck.hpp"
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <vector>
#include "lidarloop/core/angles.hpp"
#include "lidarloop/io/detail/binary_io.hpp"
#include "lidarloop/io/detail/rotation_check.hpp"
#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {
namespace {

constexpr double kCmPerM = 100.0;

// The axis permutation of FromOsnabrueckCoordinates without the unit change (det -1).
Eigen::Matrix3d AxesFromOsnabrueck() {
    Eigen::Matrix3d c;
    c << 0, 0, 1,  //
        -1, 0, 0,  //
        0, 1, 0;
    return c;
}

core::Transform FromOsnabrueckTransform(const Eigen::Matrix3d& R, const Eigen::Vector3d& t_cm) {
    const Eigen::Matrix3d C = AxesFromOsnabrueck();
    core::Transform T = core::Transform::Identity();
    T.linear() = C * R * C.transpose();  // C^-1 = C^T: C is a signed permutation
    T.translation() = FromOsnabrueckCoordinates(t_cm);
    return T;
}

Eigen::Matrix3d EulerToRotation(const Eigen::Vector3d& angles_rad) {
    return (Eigen::AngleAxisd(angles_rad.x(), Eigen::Vector3d::UnitX()) *
            Eigen::AngleAxisd(angles_rad.y(), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(angles_rad.z(), Eigen::Vector3d::UnitZ()))
        .toRotationMatrix();
}

// Inverse of EulerToRotation. Peeling off Rx first leaves Ry Rz, whose row 1 is (sin rz, cos rz, 0)
// whatever ry is, so there is no special case at ry = +-90 degrees (rx is then 0).
Eigen::Vector3d RotationToEuler(const Eigen::Matrix3d& R) {
    const double rx = std::atan2(-R(1, 2), R(2, 2));
    const Eigen::Matrix3d R_yz =
        Eigen::AngleAxisd(rx, Eigen::Vector3d::UnitX()).toRotationMatrix().transpose() * R;
    const double ry = std::atan2(R_yz(0, 2), R_yz(2, 2));
    const double rz = std::atan2(R_yz(1, 0), R_yz(1, 1));
    return {rx, ry, rz};
}

// Reads the next line; text files hold no control characters but tabs, so one means binary input.
bool NextTextLine(detail::LineReader& reader, std::string& line) {
    if (!reader.Next(line)) return false;
    detail::RejectControlCharacters(reader, line, "3DTK text file");
    return true;
}

core::Transform FramesLineToTransform(const detail::LineReader& reader, const double* values) {
    const Eigen::Map<const Eigen::Matrix4d> M(values);  // Eigen's default is column-major too
    const Eigen::RowVector4d bottom = M.row(3);
    if ((bottom - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9) {
        reader.Fail(
            "bottom row of the column-major 4x4 matrix (values 4, 8, 12, 16) is not "
            "0 0 0 1; not a rigid transform");
    }
    return FromOsnabrueckTransform(detail::NearestRotationOrFail(reader, M.topLeftCorner<3, 3>()),
                                   M.topRightCorner<3, 1>());
}

bool IsDimensionsHeader(const std::vector<std::string_view>& fields) {
    return fields.size() == 3 && fields[1] == "x" && detail::ParseSize(fields[0]) &&
           detail::ParseSize(fields[2]);
}

void AppendVector(std::string& text, const Eigen::Vector3d& v) {
    detail::AppendNumber(text, v.x(), ' ');
    detail::AppendNumber(text, v.y(), ' ');
    detail::AppendNumber(text, v.z(), '\n');
}

}  // namespace

Eigen::Vector3d FromOsnabrueckCoordinates(const Eigen::Vector3d& p_3dtk_cm) {
    return {p_3dtk_cm.z() / kCmPerM, -p_3dtk_cm.x() / kCmPerM, p_3dtk_cm.y() / kCmPerM};
}

Eigen::Vector3d ToOsnabrueckCoordinates(const Eigen::Vector3d& p_m) {
    return {-p_m.y() * kCmPerM, p_m.z() * kCmPerM, p_m.x() * kCmPerM};
}

core::PointCloud ReadOsnabrueck3d(const std::filesystem::path& file) {
    detail::LineReader reader(file);
    core::PointCloud cloud;
    std::string line;
    bool first_data_line = true;
    while (NextTextLine(reader, line)) {
        const auto fields = detail::SplitFields(line);
        if (fields.empty() || fields.front().starts_with('#')) continue;
        const bool is_header = first_data_line && IsDimensionsHeader(fields);
        first_data_line = false;
        if (is_header) continue;
        double p[3];
        reader.ParseXyz(fields, p);
        // ToFloat: a plain narrowing is undefined beyond the float range (1e41 cm in a file).
        const Eigen::Vector3d point_m = FromOsnabrueckCoordinates({p[0], p[1], p[2]});
        cloud.emplace_back(detail::ToFloat(point_m.x()), detail::ToFloat(point_m.y()),
                           detail::ToFloat(point_m.z()));
    }
    return cloud;
}

void WriteOsnabrueck3d(const std::filesystem::path& file, const core::PointCloud& cloud) {
    std::string text;
    text.reserve(cloud.size() * 48);
    // Full double digits of the cm values, so reading back gives the same float metres.
    for (const auto& point : cloud)
        AppendVector(text, ToOsnabrueckCoordinates(point.cast<double>()));
    detail::WriteTextFile(file, text);
}

core::Transform ReadOsnabrueckPose(const std::filesystem::path& file) {
    detail::LineReader reader(file);
    std::vector<double> values;  // x y z (cm), rx ry rz (degrees)
    std::string line;
    while (NextTextLine(reader, line)) {
        const auto fields = detail::SplitFields(line);
        std::vector<double> parsed(fields.size());
        reader.ParseFiniteNumbers(fields, fields.size(), parsed.data());
        if (values.size() + parsed.size() > 6) {
            reader.Fail("more than 6 numbers; a .pose file holds x y z (cm) and rx ry rz (deg)");
        }
        values.insert(values.end(), parsed.begin(), parsed.end());
    }
    if (values.size() != 6) {
        throw ReadError(file, "holds " + std::to_string(values.size()) +
                                  " numbers; a .pose file holds 6: x y z (cm), rx ry rz (deg)");
    }
    const Eigen::Vector3d t_cm(values[0], values[1], values[2]);
    const Eigen::Vector3d angles_deg(values[3], values[4], values[5]);
    return FromOsnabrueckTransform(EulerToRotation(angles_deg * core::kRadiansPerDegree), t_cm);
}

void WriteOsnabrueckPose(const std::filesystem::path& file, const core::Transform& T_world_sensor) {
    const Eigen::Matrix3d C = AxesFromOsnabrueck();
    const Eigen::Matrix3d R_3dtk = C.transpose() * T_world_sensor.linear() * C;
    std::string text;
    AppendVector(text, ToOsnabrueckCoordinates(T_world_sensor.translation()));
    AppendVector(text, RotationToEuler(R_3dtk) / core::kRadiansPerDegree);
    detail::WriteTextFile(file, text);
}

core::Transform ReadOsnabrueckFrames(const std::filesystem::path& file) {
    detail::LineReader reader(file);
    std::optional<core::Transform> last;
    std::string line;
    while (NextTextLine(reader, line)) {
        const auto fields = detail::SplitFields(line);
        if (fields.empty()) continue;
        if (fields.size() != 16 && fields.size() != 17) {
            reader.Fail("expected 16 matrix values and a colour code, got " +
                        std::to_string(fields.size()) + " values");
        }
        double values[17];
        reader.ParseFiniteNumbers(fields, fields.size(), values);
        last = FramesLineToTransform(reader, values);
    }
    if (!last) throw ReadError(file, "holds no frames (lines of 16 matrix values and a code)");
    return *last;
}

}  // namespace lidarloop::io

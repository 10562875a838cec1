#include "lidarloop/io/ros_messages.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <Eigen/Geometry>

#include "lidarloop/core/error.hpp"

namespace lidarloop::io {
namespace {

// Reads the ROS 1 wire format: little-endian scalars, uint32-prefixed strings and arrays.
class WireReader {
public:
    explicit WireReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

    std::span<const std::uint8_t> Bytes(std::size_t n, const char* what) {
        if (n > bytes_.size() - pos_) {
            throw core::FormatError("the message ends at byte " + std::to_string(bytes_.size()) +
                                    ", inside " + what + " (" + std::to_string(n) +
                                    " bytes from byte " + std::to_string(pos_) + ")");
        }
        const auto bytes = bytes_.subspan(pos_, n);
        pos_ += n;
        return bytes;
    }
    template <typename T>
    T Scalar(const char* what) {
        T value;
        std::memcpy(&value, Bytes(sizeof(T), what).data(), sizeof(T));  // x86 and ARM: LE
        return value;
    }
    std::uint32_t U32(const char* what) { return Scalar<std::uint32_t>(what); }
    std::string String(const char* what) {
        const auto bytes = Bytes(U32(what), what);
        return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
    }
    std::size_t remaining() const { return bytes_.size() - pos_; }

private:
    std::span<const std::uint8_t> bytes_;
    std::size_t pos_ = 0;
};

// std_msgs/Header: seq, stamp (sec, nsec), frame_id.
double ReadStamp(WireReader& in) {
    in.U32("header.seq");
    const std::uint32_t sec = in.U32("header.stamp");
    const std::uint32_t nsec = in.U32("header.stamp");
    return static_cast<double>(sec) + 1e-9 * static_cast<double>(nsec);
}

const PointField* FindField(const PointCloud2Message& cloud, const char* name) {
    for (const PointField& field : cloud.fields) {
        if (field.name == name) return &field;
    }
    return nullptr;
}

struct Coordinate {
    std::uint32_t offset;
    bool is_double;
};

Coordinate CoordinateOf(const PointCloud2Message& cloud, const char* name) {
    const PointField* field = FindField(cloud, name);
    if (field != nullptr && std::count_if(cloud.fields.begin(), cloud.fields.end(),
                                          [&](const PointField& f) { return f.name == name; }) > 1)
        throw core::FormatError("the cloud names field " + std::string(name) +
                                " twice: which one holds the coordinate cannot be told");
    if (field == nullptr) {
        std::string names;
        for (const PointField& f : cloud.fields) names += (names.empty() ? "" : " ") + f.name;
        throw core::FormatError("the cloud has no field " + std::string(name) +
                                " (fields: " + core::Quoted(names) + ")");
    }
    const auto type = static_cast<PointFieldType>(field->datatype);
    if (type != PointFieldType::kFloat32 && type != PointFieldType::kFloat64) {
        throw core::FormatError("field " + std::string(name) + " has datatype " +
                                std::to_string(field->datatype) +
                                "; coordinates must be FLOAT32 (7) or FLOAT64 (8)");
    }
    const bool is_double = type == PointFieldType::kFloat64;
    const std::uint64_t end = std::uint64_t{field->offset} + (is_double ? 8U : 4U);
    if (end > cloud.point_step) {
        throw core::FormatError("field " + std::string(name) + " at offset " +
                                std::to_string(field->offset) + " runs past point_step " +
                                std::to_string(cloud.point_step));
    }
    return {field->offset, is_double};
}

double ReadCoordinate(const std::uint8_t* point, const Coordinate& c) {
    if (c.is_double) {
        double value;
        std::memcpy(&value, point + c.offset, sizeof(value));
        return value;
    }
    float value;
    std::memcpy(&value, point + c.offset, sizeof(value));
    return value;
}

void CheckLayout(const PointCloud2Message& cloud) {
    if (cloud.is_bigendian) {
        throw core::FormatError(
            "the cloud is big-endian (is_bigendian true); lidarloop reads "
            "little-endian clouds only");
    }
    const std::uint64_t row_bytes = std::uint64_t{cloud.width} * cloud.point_step;
    if (row_bytes > cloud.row_step) {
        throw core::FormatError("rows of " + std::to_string(cloud.width) + " points of " +
                                std::to_string(cloud.point_step) + " bytes exceed row_step " +
                                std::to_string(cloud.row_step));
    }
    const std::uint64_t data_bytes = std::uint64_t{cloud.height} * cloud.row_step;
    if (data_bytes > cloud.data.size()) {
        throw core::FormatError("height " + std::to_string(cloud.height) + " x row_step " +
                                std::to_string(cloud.row_step) + " needs " +
                                std::to_string(data_bytes) + " bytes of data, the message has " +
                                std::to_string(cloud.data.size()));
    }
}

}  // namespace

PointCloud2Message ParsePointCloud2(std::span<const std::uint8_t> message) {
    WireReader in(message);
    PointCloud2Message cloud;
    cloud.stamp_s = ReadStamp(in);
    cloud.frame_id = in.String("header.frame_id");
    cloud.height = in.U32("height");
    cloud.width = in.U32("width");
    const std::uint32_t n_fields = in.U32("fields");
    // Each field takes at least 13 bytes: a count beyond the message is damage, not a reserve.
    if (n_fields > in.remaining() / 13) {
        throw core::FormatError("the message claims " + std::to_string(n_fields) +
                                " fields, more than its " + std::to_string(in.remaining()) +
                                " remaining bytes hold");
    }
    cloud.fields.resize(n_fields);
    for (PointField& field : cloud.fields) {
        field.name = in.String("fields.name");
        field.offset = in.U32("fields.offset");
        field.datatype = in.Scalar<std::uint8_t>("fields.datatype");
        field.count = in.U32("fields.count");
    }
    cloud.is_bigendian = in.Scalar<std::uint8_t>("is_bigendian") != 0;
    cloud.point_step = in.U32("point_step");
    cloud.row_step = in.U32("row_step");
    cloud.data = in.Bytes(in.U32("data"), "data");
    return cloud;
}

double ParseHeaderStamp(std::span<const std::uint8_t> message) {
    WireReader in(message);
    return ReadStamp(in);
}

core::PointCloud DecodePointCloud2(const PointCloud2Message& cloud) {
    const Coordinate x = CoordinateOf(cloud, "x");
    const Coordinate y = CoordinateOf(cloud, "y");
    const Coordinate z = CoordinateOf(cloud, "z");
    CheckLayout(cloud);
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    core::PointCloud points;
    points.reserve(std::size_t{cloud.height} * cloud.width);
    for (std::size_t row = 0; row < cloud.height; ++row) {
        const std::uint8_t* point = cloud.data.data() + row * cloud.row_step;
        for (std::size_t column = 0; column < cloud.width; ++column, point += cloud.point_step) {
            const Eigen::Vector3d p(ReadCoordinate(point, x), ReadCoordinate(point, y),
                                    ReadCoordinate(point, z));
            // No return (NaN, Inf), or a double that no float holds.
            if (!p.allFinite() || p.cwiseAbs().maxCoeff() > kFloatMax) continue;
            points.push_back(p.cast<float>());
        }
    }
    return points;
}

core::StampedPose ParseOdometry(std::span<const std::uint8_t> message) {
    WireReader in(message);
    core::StampedPose pose;
    pose.time_s = ReadStamp(in);
    in.String("header.frame_id");
    in.String("child_frame_id");
    double values[7];  // position x y z, orientation x y z w
    for (double& value : values) value = in.Scalar<double>("pose.pose");
    for (const double value : values) {
        if (!std::isfinite(value)) throw core::FormatError("the pose is not finite");
    }
    Eigen::Quaterniond q(values[6], values[3], values[4], values[5]);
    const double norm = q.norm();
    if (!(norm >= 0.9 && norm <= 1.1)) {
        throw core::FormatError("the orientation's quaternion has norm " + std::to_string(norm) +
                                ", not 1");
    }
    pose.T_world_sensor = core::Transform::Identity();
    pose.T_world_sensor.linear() = q.normalized().toRotationMatrix();
    pose.T_world_sensor.translation() = Eigen::Vector3d(values[0], values[1], values[2]);
    return pose;
}

}  // namespace lidarloop::io

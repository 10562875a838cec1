// The ROS 1 message decoder against messages built here byte by byte (ROS 1 wire format).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/ros_messages.hpp"

namespace lidarloop::io {
namespace {

// Appends values in the ROS 1 wire format (little-endian; uint32 length before strings).
struct Wire {
    std::vector<std::uint8_t> bytes;
    template <typename T>
    Wire& Put(T value) {
        const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
        bytes.insert(bytes.end(), p, p + sizeof(T));
        return *this;
    }
    Wire& String(const std::string& text) {
        Put(static_cast<std::uint32_t>(text.size()));
        bytes.insert(bytes.end(), text.begin(), text.end());
        return *this;
    }
    Wire& Header(std::uint32_t sec, std::uint32_t nsec) {
        return Put(std::uint32_t{7}).Put(sec).Put(nsec).String("velodyne");
    }
};

struct Field {
    std::string name;
    std::uint32_t offset;
    PointFieldType type;
};

// A PointCloud2 of `points` (each row-major `values` per point), each value written as `type`
// of its field, with `point_step`/`row_step` padding.
struct CloudSpec {
    std::uint32_t height = 1;
    std::uint32_t width = 0;
    std::vector<Field> fields;
    std::uint32_t point_step = 12;
    std::uint32_t row_step = 0;  // 0: width * point_step
    bool big_endian = false;
    std::vector<std::vector<double>> points;  // per point, one value per field
};

std::vector<std::uint8_t> Serialise(const CloudSpec& spec) {
    const std::uint32_t row_step =
        spec.row_step != 0 ? spec.row_step : spec.width * spec.point_step;
    // Room for every point even when row_step is too short for them, and 8 bytes more for a
    // field placed past point_step (layouts under test).
    const std::size_t row_bytes = std::max<std::size_t>(row_step, spec.width * spec.point_step);
    std::vector<std::uint8_t> data(spec.height * row_bytes + 8, 0xAB);  // padding: garbage

    for (std::size_t i = 0; i < spec.points.size(); ++i) {
        const std::size_t row = i / spec.width;
        const std::size_t column = i % spec.width;
        std::uint8_t* point = data.data() + row * row_bytes + column * spec.point_step;
        for (std::size_t f = 0; f < spec.fields.size(); ++f) {
            const double value = spec.points[i][f];
            if (spec.fields[f].type == PointFieldType::kFloat64) {
                std::memcpy(point + spec.fields[f].offset, &value, 8);
            } else {
                const auto single = static_cast<float>(value);
                std::memcpy(point + spec.fields[f].offset, &single, 4);
            }
        }
    }
    Wire wire;
    wire.Header(1700000000, 250000000).Put(spec.height).Put(spec.width);
    wire.Put(static_cast<std::uint32_t>(spec.fields.size()));
    for (const Field& field : spec.fields) {
        wire.String(field.name).Put(field.offset).Put(static_cast<std::uint8_t>(field.type));
        wire.Put(std::uint32_t{1});
    }
    wire.Put(static_cast<std::uint8_t>(spec.big_endian)).Put(spec.point_step).Put(row_step);
    wire.Put(static_cast<std::uint32_t>(data.size()));
    wire.bytes.insert(wire.bytes.end(), data.begin(), data.end());
    wire.Put(std::uint8_t{1});  // is_dense
    return wire.bytes;
}

core::PointCloud Decode(const std::vector<std::uint8_t>& message) {
    return DecodePointCloud2(ParsePointCloud2(message));
}

std::string DecodeError(const CloudSpec& spec) {
    try {
        Decode(Serialise(spec));
    } catch (const core::FormatError& e) {
        return e.what();
    }
    return "no error";
}

CloudSpec Float32Xyz() {
    CloudSpec spec;
    spec.fields = {{"x", 0, PointFieldType::kFloat32},
                   {"y", 4, PointFieldType::kFloat32},
                   {"z", 8, PointFieldType::kFloat32}};
    spec.width = 3;
    spec.points = {{1.5, -2.0, 0.25}, {10.0, 20.0, -3.0}, {-0.5, 0.0, 7.0}};
    return spec;
}

void ExpectPoints(const core::PointCloud& cloud, const std::vector<std::vector<double>>& points) {
    ASSERT_EQ(cloud.size(), points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(cloud[i][k], static_cast<float>(points[i][k])) << "point " << i;
        }
    }
}

TEST(RosMessages, Float32XyzAndTheStamp) {
    const CloudSpec spec = Float32Xyz();
    const std::vector<std::uint8_t> message = Serialise(spec);
    const PointCloud2Message parsed = ParsePointCloud2(message);
    EXPECT_DOUBLE_EQ(parsed.stamp_s, 1700000000.25);
    EXPECT_DOUBLE_EQ(ParseHeaderStamp(message), 1700000000.25);
    EXPECT_EQ(parsed.frame_id, "velodyne");
    ExpectPoints(DecodePointCloud2(parsed), spec.points);
}

TEST(RosMessages, Float64FieldsInAnyOrderWithPadding) {
    CloudSpec spec;
    // Ouster-like: intensity first, z before x, 48-byte points with unused bytes.
    spec.fields = {{"intensity", 0, PointFieldType::kFloat32},
                   {"z", 8, PointFieldType::kFloat64},
                   {"x", 16, PointFieldType::kFloat64},
                   {"y", 32, PointFieldType::kFloat64}};
    spec.point_step = 48;
    spec.width = 2;
    spec.points = {{0.5, 3.0, 1.0, 2.0}, {0.7, -6.0, 4.0, 5.0}};
    ExpectPoints(Decode(Serialise(spec)), {{1.0, 2.0, 3.0}, {4.0, 5.0, -6.0}});
}

TEST(RosMessages, OrganisedCloudWithRowPaddingDropsNanAndInfPoints) {
    CloudSpec spec = Float32Xyz();
    spec.fields.push_back({"ring", 12, PointFieldType::kUint16});
    spec.point_step = 16;
    spec.height = 2;
    spec.width = 2;
    spec.row_step = 40;  // 8 bytes of padding after each row
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    spec.points = {{1, 2, 3, 0}, {nan, nan, nan, 0}, {4, inf, 6, 1}, {7, 8, 9, 1}};
    ExpectPoints(Decode(Serialise(spec)), {{1, 2, 3}, {7, 8, 9}});
}

TEST(RosMessages, EmptyCloudGivesNoPoints) {
    CloudSpec spec = Float32Xyz();
    spec.width = 0;
    spec.points.clear();
    EXPECT_TRUE(Decode(Serialise(spec)).empty());
}

TEST(RosMessages, RefusesBigEndianClouds) {
    CloudSpec spec = Float32Xyz();
    spec.big_endian = true;
    EXPECT_NE(DecodeError(spec).find("big-endian"), std::string::npos) << DecodeError(spec);
}

TEST(RosMessages, NamesAMissingCoordinateAndTheFieldsThereAre) {
    CloudSpec spec = Float32Xyz();
    spec.fields[2].name = "intensity";
    const std::string error = DecodeError(spec);
    EXPECT_NE(error.find("no field z"), std::string::npos) << error;
    EXPECT_NE(error.find("'x y intensity'"), std::string::npos) << error;
}

TEST(RosMessages, RefusesACoordinateNamedTwice) {
    CloudSpec spec = Float32Xyz();
    spec.fields[2].name = "x";
    const std::string error = DecodeError(spec);
    EXPECT_NE(error.find("names field x twice"), std::string::npos) << error;
}

TEST(RosMessages, RefusesIntegerCoordinates) {
    CloudSpec spec = Float32Xyz();
    spec.fields[0].type = PointFieldType::kInt16;
    EXPECT_NE(DecodeError(spec).find("field x has datatype 3"), std::string::npos)
        << DecodeError(spec);
}

TEST(RosMessages, RefusesLayoutsThatDoNotFit) {
    CloudSpec beyond_step = Float32Xyz();
    beyond_step.fields[2].offset = 10;  // 10 + 4 > point_step 12
    EXPECT_NE(DecodeError(beyond_step).find("runs past point_step"), std::string::npos);
    CloudSpec short_rows = Float32Xyz();
    short_rows.row_step = 24;  // 3 points of 12 bytes
    EXPECT_NE(DecodeError(short_rows).find("exceed row_step"), std::string::npos);
    // A height the data does not hold: the message claims 2 rows, serialises 1.
    std::vector<std::uint8_t> message = Serialise(Float32Xyz());
    const std::uint32_t height = 2;
    std::memcpy(message.data() + 4 + 8 + 4 + 8, &height, 4);  // after seq, stamp, frame_id
    try {
        Decode(message);
        ADD_FAILURE() << "no error";
    } catch (const core::FormatError& e) {
        EXPECT_NE(std::string(e.what()).find("bytes of data"), std::string::npos) << e.what();
    }
}

TEST(RosMessages, EveryTruncationIsAFormatError) {
    const std::vector<std::uint8_t> message = Serialise(Float32Xyz());
    for (std::size_t size = 0; size + 1 < message.size(); ++size) {  // the last byte: is_dense
        const std::vector<std::uint8_t> cut(message.begin(),
                                            message.begin() + static_cast<std::ptrdiff_t>(size));
        EXPECT_THROW(ParsePointCloud2(cut), core::FormatError) << size << " bytes";
    }
}

std::vector<std::uint8_t> Odometry(double x, double qz, double qw) {
    Wire wire;
    wire.Header(12, 500000000).String("base_link");  // frame_id, then child_frame_id
    for (const double value : {x, 2.0, 3.0, 0.0, 0.0, qz, qw}) wire.Put(value);
    for (int i = 0; i < 36; ++i) wire.Put(0.0);  // pose covariance; the twist is not read
    return wire.bytes;
}

TEST(RosMessages, OdometryPoseAndStamp) {
    const double half = std::sqrt(0.5);
    const core::StampedPose pose = ParseOdometry(Odometry(1.0, half, half));  // 90 deg about z
    EXPECT_DOUBLE_EQ(pose.time_s, 12.5);
    EXPECT_TRUE(pose.T_world_sensor.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
    EXPECT_TRUE((pose.T_world_sensor.linear() * Eigen::Vector3d::UnitX())
                    .isApprox(Eigen::Vector3d::UnitY(), 1e-12));
    EXPECT_THROW(ParseOdometry(Odometry(std::nan(""), 0, 1)), core::FormatError);
    EXPECT_THROW(ParseOdometry(Odometry(1.0, 0, 0)), core::FormatError);  // zero quaternion
    const std::vector<std::uint8_t> full = Odometry(1.0, 0, 1);
    EXPECT_THROW(ParseOdometry(std::span(full).first(40)), core::FormatError);
}

}  // namespace
}  // namespace lidarloop::io

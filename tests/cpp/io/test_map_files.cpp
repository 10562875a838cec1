// Map files: the PLY of a map read back with ReadPly and byte by byte, the top view decoded with
// libpng, the colour map's ends, and what lidarloop recognises as its own PLY.
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <png.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/colour_map.hpp"
#include "lidarloop/io/map_files.hpp"
#include "lidarloop/io/map_image.hpp"
#include "lidarloop/io/ply.hpp"
#include "lidarloop/io/png.hpp"
#include "lidarloop/io/read_error.hpp"
#include "test_utils.hpp"

namespace lidarloop::io {
namespace {

core::MapCloud TestMap(double offset_x = 0.0) {
    core::MapCloud map;
    for (int i = 0; i < 50; ++i) {
        map.points.push_back(
            {Eigen::Vector3d(offset_x + 0.5 * i, 0.25 * i, -1.0 + 0.1 * i), 10.0 + 0.2 * i});
    }
    map.voxel_m = 0.2;
    map.scans = 3;
    map.input_points = 500;
    map.first_time_s = 10.0;
    map.last_time_s = 10.0 + 0.2 * 49;
    return map;
}

// The decoded RGB pixels of a PNG file (libpng's simplified API), width and height.
struct Decoded {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;
};

Decoded DecodePng(const std::filesystem::path& file) {
    png_image image;
    std::memset(&image, 0, sizeof(image));
    image.version = PNG_IMAGE_VERSION;
    Decoded decoded;
    if (!png_image_begin_read_from_file(&image, file.c_str())) return decoded;
    image.format = PNG_FORMAT_RGB;
    decoded.rgb.resize(PNG_IMAGE_SIZE(image));
    if (!png_image_finish_read(&image, nullptr, decoded.rgb.data(), 0, nullptr)) return {};
    decoded.width = static_cast<int>(image.width);
    decoded.height = static_cast<int>(image.height);
    return decoded;
}

TEST(MapPly, ReadsBackWithItsColoursAndTimes) {
    test::TempDir dir;
    const core::MapCloud map = TestMap();
    WriteMapPly(dir / "map.ply", map);
    const core::PointCloud read = ReadPly(dir / "map.ply");
    ASSERT_EQ(read.size(), map.points.size());
    for (std::size_t i = 0; i < read.size(); ++i) {
        EXPECT_EQ(read[i], map.points[i].position.cast<float>()) << i;
    }
    const std::string bytes = test::ReadFile(dir / "map.ply");
    EXPECT_TRUE(test::Contains(bytes, "comment written by lidarloop\n"));
    EXPECT_TRUE(test::Contains(bytes, "property uchar red\n"));
    // The first vertex: x y z floats, then the colour of the first time (viridis at 0) and
    // the time as a double.
    const std::size_t data = bytes.find("end_header\n") + 11;
    ASSERT_EQ(bytes.size(), data + map.points.size() * (12 + 3 + 8));
    EXPECT_EQ(static_cast<std::uint8_t>(bytes[data + 12]), Viridis(0.0)[0]);
    EXPECT_EQ(static_cast<std::uint8_t>(bytes[data + 13]), Viridis(0.0)[1]);
    const std::size_t last = data + (map.points.size() - 1) * 23;
    EXPECT_EQ(static_cast<std::uint8_t>(bytes[last + 14]), Viridis(1.0)[2]);
    double time = 0.0;
    std::memcpy(&time, bytes.data() + last + 15, sizeof(time));
    EXPECT_DOUBLE_EQ(time, map.points.back().time_s);
    EXPECT_TRUE(IsLidarloopPly(dir / "map.ply"));
}

// Far from the origin a float keeps less than a centimetre: the coordinates become doubles.
TEST(MapPly, FarCoordinatesAreDoubles) {
    test::TempDir dir;
    const core::MapCloud map = TestMap(500000.25);
    WriteMapPly(dir / "utm.ply", map);
    EXPECT_TRUE(test::Contains(test::ReadFile(dir / "utm.ply"), "property double x\n"));
    EXPECT_EQ(ReadPly(dir / "utm.ply").size(), map.points.size());
    core::MapCloud empty;
    WriteMapPly(dir / "empty.ply", empty);
    EXPECT_TRUE(ReadPly(dir / "empty.ply").empty());
    EXPECT_THROW(WriteMapPly(dir / "no" / "such" / "map.ply", map), WriteError);
}

TEST(MapPly, OnlyItsOwnPlyCountsAsLidarloops) {
    test::TempDir dir;
    test::WriteFile(dir / "other.ply",
                    "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 0\n"
                    "property float x\nproperty float y\nproperty float z\nend_header\n");
    test::WriteFile(dir / "text.ply", "not a ply\ncomment written by lidarloop\n");
    EXPECT_FALSE(IsLidarloopPly(dir / "other.ply"));
    EXPECT_FALSE(IsLidarloopPly(dir / "text.ply"));
    EXPECT_FALSE(IsLidarloopPly(dir / "missing.ply"));
    WritePly(dir / "scan.ply", core::PointCloud{{1, 2, 3}}, PlyEncoding::kAscii,
             PlyScalar::kFloat32);
    EXPECT_TRUE(IsLidarloopPly(dir / "scan.ply"));
}

TEST(Viridis, EndsAndClamping) {
    EXPECT_EQ(Viridis(0.0), (Rgb{68, 1, 84}));
    EXPECT_EQ(Viridis(1.0), (Rgb{253, 231, 37}));
    EXPECT_EQ(Viridis(-3.0), Viridis(0.0));
    EXPECT_EQ(Viridis(7.0), Viridis(1.0));
    EXPECT_EQ(Viridis(std::nan("")), (Rgb{128, 128, 128}));
}

// Two maps at one scale: a map shifted by 10 m is drawn 10 m further right in its panel; the
// PNG decodes to the size MapTopView gave.
TEST(MapTopView, PanelsShareScaleAndExtent) {
    test::TempDir dir;
    core::MapCloud a = TestMap();
    core::MapCloud b = TestMap(10.0);
    const Image image = MapTopView({{"odometry", &a}, {"optimised", &b}}, 400);
    ASSERT_EQ(image.channels, 3);
    WritePng(dir / "map.png", image);
    const Decoded decoded = DecodePng(dir / "map.png");
    ASSERT_EQ(decoded.width, image.width);
    ASSERT_EQ(decoded.height, image.height);
    EXPECT_EQ(decoded.rgb, image.pixels);
    // Extent x 0..34.5 m, y 0..12.25 m plus 2 %: 400 pixels across both panels' width.
    EXPECT_GT(image.width, 2 * 400);
    EXPECT_LT(image.height, 400);
    // Columns of the panels that hold a coloured (not white, not grey frame) pixel.
    auto coloured_columns = [&](int from, int to) {
        std::vector<int> columns;
        for (int x = from; x < to; ++x) {
            for (int y = 50; y < image.height - 80; ++y) {
                const std::size_t at = (static_cast<std::size_t>(y) * image.width + x) * 3;
                const auto r = image.pixels[at], g = image.pixels[at + 1],
                           bl = image.pixels[at + 2];
                if (!(r == g && g == bl)) {
                    columns.push_back(x - from);
                    break;
                }
            }
        }
        return columns;
    };
    const int panel = (image.width - 2 * 16 - 24) / 2;
    const std::vector<int> left = coloured_columns(16, 16 + panel);
    const std::vector<int> right = coloured_columns(16 + panel + 24, image.width - 16);
    ASSERT_FALSE(left.empty());
    ASSERT_FALSE(right.empty());
    const double m_per_px = (34.5 + 0.04 * 34.5) / 400.0;
    EXPECT_NEAR((right.front() - left.front()) * m_per_px, 10.0, 2 * m_per_px);
}

TEST(MapTopView, EmptyMapsAndBadArgumentsAreHandled) {
    const core::MapCloud empty;
    const Image image = MapTopView({{"nothing", &empty}});
    EXPECT_GT(image.width, 0);
    EXPECT_EQ(image.pixels.size(), static_cast<std::size_t>(image.width) * image.height * 3);
    EXPECT_THROW(MapTopView({}), core::ConfigError);
    EXPECT_THROW(MapTopView({{"null", nullptr}}), core::ConfigError);
    EXPECT_THROW(MapTopView({{"tiny", &empty}}, 10), core::ConfigError);
}

}  // namespace
}  // namespace lidarloop::io

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "io/io_test_utils.hpp"
#include "lidarloop/io/xyz.hpp"

namespace lidarloop::io {
namespace {

using test::Contains;
using test::ReadErrorOf;

std::string XyzErrorOf(const test::TempDir& dir, const std::string& text) {
    test::WriteFile(dir / "bad.xyz", text);
    return ReadErrorOf([&] { ReadXyz(dir / "bad.xyz"); });
}

TEST(Xyz, ReadsSeparatorsCommentsAndExtraColumns) {
    test::TempDir dir;
    test::WriteFile(dir / "a.xyz",
                    "# x y z\n// exported\n\n1 2 3\n4,5,6,99\n\t7\t8.5\t-9e-1 extra text\r\n"
                    "  # indented comment\n+1.25 -0 1e2\n");
    const core::PointCloud expected = {
        {1.0f, 2.0f, 3.0f}, {4.0f, 5.0f, 6.0f}, {7.0f, 8.5f, -0.9f}, {1.25f, 0.0f, 100.0f}};
    EXPECT_EQ(ReadXyz(dir / "a.xyz"), expected);
}

TEST(Xyz, SkipsTheLeicaPtsPointCountLine) {
    test::TempDir dir;
    test::WriteFile(dir / "a.pts", "2\n1 2 3 -1200 10 20 30\n4 5 6 -1100 40 50 60\n");
    const core::PointCloud expected = {{1.0f, 2.0f, 3.0f}, {4.0f, 5.0f, 6.0f}};
    EXPECT_EQ(ReadXyz(dir / "a.pts"), expected);
}

TEST(Xyz, RoundTripIsExactForRandomCloud) {
    test::TempDir dir;
    const core::PointCloud cloud = test::RandomCloud(2000, 11, 150.0f);
    WriteXyz(dir / "a.xyz", cloud);
    EXPECT_EQ(ReadXyz(dir / "a.xyz"), cloud);
}

// Text parsed as double and narrowed must give the same float back, at every exponent.
TEST(Xyz, RoundTripIsExactForFloatsOfAllMagnitudes) {
    test::TempDir dir;
    std::mt19937 rng(5);
    core::PointCloud cloud;
    while (cloud.size() < 20000) {
        Eigen::Vector3f p;
        for (int axis = 0; axis < 3; ++axis) p[axis] = std::bit_cast<float>(std::uint32_t(rng()));
        if (p.allFinite()) cloud.push_back(p);
    }
    cloud.push_back({std::numeric_limits<float>::max(), std::numeric_limits<float>::denorm_min(),
                     -std::numeric_limits<float>::min()});
    // 7.038531e-26f: its shortest float text, read as a double and narrowed, is one ulp off.
    const float double_rounding_trap = std::bit_cast<float>(std::uint32_t{0x15ae43fd});
    cloud.push_back({double_rounding_trap, -double_rounding_trap, 1.0f});
    WriteXyz(dir / "a.xyz", cloud);
    const core::PointCloud read = ReadXyz(dir / "a.xyz");
    ASSERT_EQ(read.size(), cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) ASSERT_EQ(read[i], cloud[i]) << "point " << i;
}

TEST(Xyz, KeepsNanAndInf) {
    test::TempDir dir;
    test::WriteFile(dir / "a.xyz", "nan 1 2\n1 inf -inf\n");
    const core::PointCloud cloud = ReadXyz(dir / "a.xyz");
    ASSERT_EQ(cloud.size(), 2U);
    EXPECT_TRUE(std::isnan(cloud[0].x()));
    EXPECT_EQ(cloud[0].z(), 2.0f);
    EXPECT_EQ(cloud[1].y(), std::numeric_limits<float>::infinity());
    EXPECT_EQ(cloud[1].z(), -std::numeric_limits<float>::infinity());
    WriteXyz(dir / "b.xyz", cloud);
    const core::PointCloud again = ReadXyz(dir / "b.xyz");
    ASSERT_EQ(again.size(), 2U);
    EXPECT_TRUE(std::isnan(again[0].x()));
    EXPECT_EQ(again[1], cloud[1]);
}

// Beyond the float range a plain double -> float narrowing is undefined behaviour; the reader
// rounds as IEEE does: to infinity, or down to FLT_MAX within half an ulp above it.
TEST(Xyz, NumbersBeyondTheFloatRangeBecomeInfinite) {
    test::TempDir dir;
    test::WriteFile(dir / "a.xyz", "1e39 -1e300 3.4028235e38\n");
    const core::PointCloud cloud = ReadXyz(dir / "a.xyz");
    ASSERT_EQ(cloud.size(), 1U);
    EXPECT_EQ(cloud[0].x(), std::numeric_limits<float>::infinity());
    EXPECT_EQ(cloud[0].y(), -std::numeric_limits<float>::infinity());
    EXPECT_EQ(cloud[0].z(), std::numeric_limits<float>::max());
}

TEST(Xyz, EmptyOrCommentOnlyFileGivesEmptyCloud) {
    test::TempDir dir;
    test::WriteFile(dir / "empty.xyz", "");
    test::WriteFile(dir / "comments.xyz", "# nothing\n\n// here\n");
    EXPECT_TRUE(ReadXyz(dir / "empty.xyz").empty());
    EXPECT_TRUE(ReadXyz(dir / "comments.xyz").empty());
}

TEST(Xyz, MissingFileIsAReadErrorNamingIt) {
    test::TempDir dir;
    const std::string message = ReadErrorOf([&] { ReadXyz(dir / "nope.xyz"); });
    EXPECT_TRUE(Contains(message, "nope.xyz"));
    EXPECT_TRUE(Contains(message, "no such file"));
}

TEST(Xyz, TooFewNumbersNameTheLine) {
    test::TempDir dir;
    const std::string message = XyzErrorOf(dir, "1 2 3\n# c\n4 5\n");
    EXPECT_TRUE(Contains(message, "bad.xyz: line 3"));
    EXPECT_TRUE(Contains(message, "expected at least 3 numbers, got 2"));
}

TEST(Xyz, TruncatedLastLineIsAnError) {
    test::TempDir dir;
    EXPECT_TRUE(Contains(XyzErrorOf(dir, "1 2 3\n4 5"), "line 2: expected at least 3 numbers"));
}

TEST(Xyz, NonNumberNamesTheLineAndToken) {
    test::TempDir dir;
    EXPECT_TRUE(Contains(XyzErrorOf(dir, "1 2 3\n1 abc 3\n"), "line 2: 'abc' is not a number"));
    EXPECT_TRUE(Contains(XyzErrorOf(dir, "1 2 3x\n"), "line 1: '3x' is not a number"));
}

TEST(Xyz, PcdFileGivesAClearError) {
    test::TempDir dir;
    const std::string message =
        XyzErrorOf(dir, "# .PCD v0.7 - Point Cloud Data\nVERSION 0.7\nFIELDS x y z\n");
    EXPECT_TRUE(Contains(message, "line 2: 'VERSION' is not a number"));
}

TEST(Xyz, BinaryDataIsNamedAsSuch) {
    test::TempDir dir;
    std::string bytes = "1 2 3\n";
    bytes += std::string("\x7f\x45\x4c\x46\x02\x01\x01\x00", 8);  // an ELF header
    const std::string message = XyzErrorOf(dir, bytes);
    EXPECT_TRUE(Contains(message, "line 2: holds control character 0x7f"));
    EXPECT_TRUE(Contains(message, "binary data"));
}

}  // namespace
}  // namespace lidarloop::io

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "io/io_test_utils.hpp"
#include "lidarloop/io/kitti_bin.hpp"

namespace lidarloop::io {
namespace {

using test::Contains;
using test::ReadErrorOf;

// Little-endian float32 bytes of the fixture's first record: 1.5, -2.25, 3, intensity 0.5.
const std::string kFirstRecord("\x00\x00\xc0\x3f\x00\x00\x10\xc0\x00\x00\x40\x40\x00\x00\x00\x3f",
                               16);

TEST(KittiBin, ReadsLittleEndianFixtureAndDropsIntensity) {
    const auto file = test::DataFile("kitti/000000.bin");
    ASSERT_EQ(test::ReadFile(file).substr(0, 16), kFirstRecord);
    const core::PointCloud cloud = ReadKittiBin(file);
    const core::PointCloud expected = {
        {1.5f, -2.25f, 3.0f}, {10.0f, 20.0f, -1.75f}, {0.125f, 0.0f, -0.5f}};
    EXPECT_EQ(cloud, expected);
}

TEST(KittiBin, WritesLittleEndianRecordsWithZeroIntensity) {
    test::TempDir dir;
    WriteKittiBin(dir / "scan.bin", {{1.5f, -2.25f, 3.0f}});
    std::string expected = kFirstRecord;
    expected[15] = '\0';  // intensity 0 instead of 0.5
    EXPECT_EQ(test::ReadFile(dir / "scan.bin"), expected);
}

TEST(KittiBin, RoundTripIsExact) {
    test::TempDir dir;
    const core::PointCloud cloud = test::RandomCloud(5000, 7, 80.0f);
    WriteKittiBin(dir / "scan.bin", cloud);
    EXPECT_EQ(std::filesystem::file_size(dir / "scan.bin"), 5000U * 16U);
    EXPECT_EQ(ReadKittiBin(dir / "scan.bin"), cloud);
}

TEST(KittiBin, KeepsNonFiniteValues) {
    test::TempDir dir;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    WriteKittiBin(dir / "scan.bin", {{nan, 1.0f, 2.0f}, {inf, -inf, 0.0f}});
    const core::PointCloud cloud = ReadKittiBin(dir / "scan.bin");
    ASSERT_EQ(cloud.size(), 2U);
    EXPECT_TRUE(std::isnan(cloud[0].x()));
    EXPECT_EQ(cloud[0].y(), 1.0f);
    EXPECT_EQ(cloud[1].x(), inf);
    EXPECT_EQ(cloud[1].y(), -inf);
}

TEST(KittiBin, EmptyFileGivesEmptyCloud) {
    test::TempDir dir;
    test::WriteFile(dir / "empty.bin", "");
    EXPECT_TRUE(ReadKittiBin(dir / "empty.bin").empty());
}

TEST(KittiBin, MissingFileIsAReadErrorNamingIt) {
    test::TempDir dir;
    const std::string message = ReadErrorOf([&] { ReadKittiBin(dir / "nope.bin"); });
    EXPECT_TRUE(Contains(message, "nope.bin"));
    EXPECT_TRUE(Contains(message, "no such file"));
}

TEST(KittiBin, FolderIsAReadError) {
    test::TempDir dir;
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadKittiBin(dir.path()); }), "is a folder"));
}

TEST(KittiBin, TruncatedFileNamesItsSize) {
    test::TempDir dir;
    WriteKittiBin(dir / "scan.bin", test::RandomCloud(3, 1));
    const std::string bytes = test::ReadFile(dir / "scan.bin");
    test::WriteFile(dir / "cut.bin", bytes.substr(0, 43));
    const std::string message = ReadErrorOf([&] { ReadKittiBin(dir / "cut.bin"); });
    EXPECT_TRUE(Contains(message, "cut.bin"));
    EXPECT_TRUE(Contains(message, "size 43 bytes"));
    EXPECT_TRUE(Contains(message, "truncated or not a KITTI scan"));
}

TEST(KittiBin, RandomBytesOfOddSizeAreRejected) {
    test::TempDir dir;
    std::mt19937 rng(3);
    std::string bytes(1001, '\0');
    for (char& c : bytes) c = static_cast<char>(rng() & 0xff);
    test::WriteFile(dir / "noise.bin", bytes);
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadKittiBin(dir / "noise.bin"); }),
                         "size 1001 bytes is not a multiple of 16"));
}

TEST(KittiBin, PcdOrPlyRenamedToBinIsRejected) {
    test::TempDir dir;
    std::string pcd = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n";
    pcd.resize(64, ' ');  // a multiple of 16, so only the header check can catch it
    test::WriteFile(dir / "cloud.bin", pcd);
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadKittiBin(dir / "cloud.bin"); }), "PCD header"));
    std::string ply = "ply\nformat binary_little_endian 1.0\n";
    ply.resize(48, ' ');
    test::WriteFile(dir / "mesh.bin", ply);
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadKittiBin(dir / "mesh.bin"); }), "PLY header"));
}

}  // namespace
}  // namespace lidarloop::io

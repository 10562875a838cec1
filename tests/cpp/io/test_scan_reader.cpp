#include <string>

#include <gtest/gtest.h>

#include "lidarloop/io/kitti_bin.hpp"
#include "lidarloop/io/osnabrueck.hpp"
#include "lidarloop/io/pcd.hpp"
#include "lidarloop/io/ply.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/scan_reader.hpp"
#include "lidarloop/io/xyz.hpp"
#include "test_utils.hpp"

namespace lidarloop::io {
namespace {

void ExpectNear(const core::PointCloud& a, const core::PointCloud& b, float tolerance) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_LE((a[i] - b[i]).cwiseAbs().maxCoeff(), tolerance) << "point " << i;
    }
}

TEST(ScanReader, DispatchesOnTheExtensionOfEveryFormat) {
    test::TempDir dir;
    const core::PointCloud cloud = test::RandomCloud(50, 1);
    WriteKittiBin(dir / "a.bin", cloud);
    WritePcd(dir / "a.pcd", cloud, PcdEncoding::kBinaryCompressed);
    WritePly(dir / "a.ply", cloud, PlyEncoding::kBinaryBigEndian, PlyScalar::kFloat64);
    WriteXyz(dir / "a.xyz", cloud);
    WriteXyz(dir / "a.txt", cloud);
    WriteXyz(dir / "A.PTS", cloud);
    WriteOsnabrueck3d(dir / "scan000.3d", cloud);
    for (const char* name : {"a.bin", "a.pcd", "a.ply", "a.xyz", "a.txt", "A.PTS"}) {
        ExpectNear(ReadScan(dir / name), cloud, 0.0f);
    }
    ExpectNear(ReadScan(dir / "scan000.3d"), cloud, 1e-4f);  // text in centimetres
}

TEST(ScanReader, UnknownExtensionListsKnownOnes) {
    test::TempDir dir;
    test::WriteFile(dir / "scan.las", "whatever");
    try {
        ReadScan(dir / "scan.las");
        FAIL() << "read an unknown format";
    } catch (const ReadError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("scan.las"), std::string::npos);
        EXPECT_NE(message.find("unknown scan format '.las'"), std::string::npos);
        EXPECT_NE(message.find(".pcd"), std::string::npos);
    }
    EXPECT_FALSE(IsScanFile("x.las"));
    EXPECT_TRUE(IsScanFile("x.PCD"));
}

TEST(ScanReader, MissingFileAndFolderAreErrors) {
    test::TempDir dir;
    EXPECT_THROW(ReadScan(dir / "missing.pcd"), ReadError);
    std::filesystem::create_directories(dir / "folder.pcd");
    EXPECT_THROW(ReadScan(dir / "folder.pcd"), ReadError);
}

// A poses file's twelve numbers a line would read as points (its first three): a poses, times
// or calibration file is no scan, as in a dataset folder.
TEST(ScanReader, PosesTimesAndCalibrationFilesAreNoScans) {
    test::TempDir dir;
    for (const char* name : {"poses.txt", "poses_odometry.txt", "times.txt", "calib_00.txt"}) {
        test::WriteFile(dir / name, "1 0 0 0 0 1 0 0 0 0 1 0\n");
        try {
            ReadScan(dir / name);
            FAIL() << "read " << name << " as a scan";
        } catch (const ReadError& e) {
            EXPECT_NE(std::string(e.what()).find("is named as a poses, times or calibration file"),
                      std::string::npos)
                << e.what();
        }
        EXPECT_TRUE(IsSidecarFile(dir / name));
    }
    WriteXyz(dir / "scan_poses.txt", test::RandomCloud(3, 1));
    EXPECT_EQ(ReadScan(dir / "scan_poses.txt").size(), 3U);
    EXPECT_FALSE(IsSidecarFile("poses.xyz"));
}

TEST(ScanReader, WrongContentForTheExtensionIsAnError) {
    test::TempDir dir;
    WriteXyz(dir / "text.xyz", test::RandomCloud(10, 2));
    std::filesystem::copy_file(dir / "text.xyz", dir / "text.pcd");
    std::filesystem::copy_file(dir / "text.xyz", dir / "text.ply");
    test::WriteFile(dir / "odd.bin", std::string(17, '\x01'));
    EXPECT_THROW(ReadScan(dir / "text.pcd"), ReadError);
    EXPECT_THROW(ReadScan(dir / "text.ply"), ReadError);
    EXPECT_THROW(ReadScan(dir / "odd.bin"), ReadError);
}

}  // namespace
}  // namespace lidarloop::io

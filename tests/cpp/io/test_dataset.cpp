#include <string>

#include <gtest/gtest.h>

#include "lidarloop/io/dataset.hpp"
#include "lidarloop/io/kitti_bin.hpp"
#include "lidarloop/io/osnabrueck.hpp"
#include "lidarloop/io/pcd.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/io/read_error.hpp"
#include "test_utils.hpp"

namespace lidarloop::io {
namespace fs = std::filesystem;
namespace {

std::vector<core::StampedPose> LinePoses(std::size_t count) {
    std::vector<core::StampedPose> poses(count);
    for (std::size_t i = 0; i < count; ++i) {
        poses[i].time_s = 0.1 * static_cast<double>(i);
        poses[i].T_world_sensor.translation() = Eigen::Vector3d(2.0 * static_cast<double>(i), 0, 0);
    }
    return poses;
}

std::string ErrorOf(const fs::path& path, const DatasetOptions& options = {}) {
    try {
        OpenDataset(path, options);
    } catch (const ReadError& e) {
        return e.what();
    }
    return "no error";
}

TEST(Dataset, OpensKittiLayoutWithPoses) {
    test::TempDir dir;
    fs::create_directories(dir / "velodyne");
    for (int i = 0; i < 3; ++i) {
        WriteKittiBin(dir.path() / "velodyne" / ("00000" + std::to_string(i) + ".bin"),
                      test::RandomCloud(20, static_cast<unsigned>(i)));
    }
    WriteKittiPoses(dir / "poses.txt", LinePoses(3));
    const Dataset dataset = OpenDataset(dir.path());
    EXPECT_EQ(dataset.format(), DatasetFormat::kKitti);
    EXPECT_EQ(dataset.FormatName(), "kitti");
    ASSERT_EQ(dataset.size(), 3U);
    EXPECT_EQ(dataset.ScanPath(2).filename(), "000002.bin");
    ASSERT_TRUE(dataset.HasPoses());
    EXPECT_NEAR(dataset.poses()[2].T_world_sensor.translation().x(), 4.0, 1e-9);
    EXPECT_EQ(dataset.LoadScan(1), test::RandomCloud(20, 1));
}

TEST(Dataset, OpensFolderSortedNaturallyAndSkipsSidecars) {
    test::TempDir dir;
    for (int i : {10, 2, 1}) {
        WritePcd(dir / ("scan" + std::to_string(i) + ".pcd"),
                 test::RandomCloud(5, static_cast<unsigned>(i)), PcdEncoding::kBinary);
    }
    WriteTumPoses(dir / "poses.txt", LinePoses(3));
    const Dataset dataset = OpenDataset(dir.path());
    EXPECT_EQ(dataset.format(), DatasetFormat::kFolder);
    ASSERT_EQ(dataset.size(), 3U);
    EXPECT_EQ(dataset.ScanPath(0).filename(), "scan1.pcd");
    EXPECT_EQ(dataset.ScanPath(1).filename(), "scan2.pcd");
    EXPECT_EQ(dataset.ScanPath(2).filename(), "scan10.pcd");
    EXPECT_TRUE(dataset.HasPoses());
}

TEST(Dataset, PoseAndNoteTextFilesBesideScansAreNotScans) {
    test::TempDir dir;
    for (int i = 0; i < 3; ++i) {
        WriteKittiBin(dir / ("00000" + std::to_string(i) + ".bin"),
                      test::RandomCloud(5, static_cast<unsigned>(i)));
    }
    WriteKittiPoses(dir / "poses.txt", LinePoses(3));
    WriteKittiPoses(dir / "poses_odometry.txt", LinePoses(3));
    test::WriteFile(dir / "groundtruth.txt", "1 2 3\n");
    const Dataset dataset = OpenDataset(dir.path());
    EXPECT_EQ(dataset.format(), DatasetFormat::kFolder);
    ASSERT_EQ(dataset.size(), 3U);
    EXPECT_EQ(dataset.ScanPath(2).filename(), "000002.bin");
}

TEST(Dataset, TextScansSkipPoseTimeAndCalibrationFiles) {
    test::TempDir dir;
    for (const char* name : {"a.txt", "b.txt"}) test::WriteFile(dir / name, "1 2 3\n4 5 6\n");
    test::WriteFile(dir / "calib_00.txt", "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n");
    test::WriteFile(dir / "times_lidar.txt", "0\n0.1\n");
    WriteKittiPoses(dir / "poses_odometry.txt", LinePoses(2));
    const Dataset dataset = OpenDataset(dir.path());
    ASSERT_EQ(dataset.size(), 2U);
    EXPECT_EQ(dataset.ScanPath(0).filename(), "a.txt");
    EXPECT_EQ(dataset.ScanPath(1).filename(), "b.txt");
}

TEST(Dataset, FolderOfSequencesNamesTheSequences) {
    test::TempDir dir;
    for (const char* sequence : {"08", "00"}) {
        fs::create_directories(dir / sequence / "velodyne");
        WriteKittiBin(dir / sequence / "velodyne" / "000000.bin", test::RandomCloud(5, 1));
    }
    fs::create_directories(dir / "poses");
    WriteKittiPoses(dir / "poses" / "00.txt", LinePoses(1));
    test::WriteFile(dir / "calib_00.txt", "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n");
    const std::string message = ErrorOf(dir.path());
    EXPECT_NE(message.find("cannot tell the dataset format"), std::string::npos) << message;
    EXPECT_NE(message.find("its subfolders 00, 08 hold scans"), std::string::npos) << message;
}

TEST(Dataset, OpensOsnabrueckFolderWithPoseFiles) {
    test::TempDir dir;
    for (int i = 0; i < 2; ++i) {
        const std::string stem = "scan00" + std::to_string(i);
        WriteOsnabrueck3d(dir / (stem + ".3d"), test::RandomCloud(5, static_cast<unsigned>(i)));
        core::Transform T_world_sensor = core::Transform::Identity();
        T_world_sensor.translation() = Eigen::Vector3d(i, 2.0 * i, 0.5);
        WriteOsnabrueckPose(dir / (stem + ".pose"), T_world_sensor);
    }
    const Dataset dataset = OpenDataset(dir.path());
    EXPECT_EQ(dataset.format(), DatasetFormat::kOsnabrueck);
    ASSERT_EQ(dataset.poses().size(), 2U);
    EXPECT_NEAR(dataset.poses()[1].T_world_sensor.translation().y(), 2.0, 1e-6);
}

TEST(Dataset, PoseCountMismatchIsAnError) {
    test::TempDir dir;
    fs::create_directories(dir / "velodyne");
    WriteKittiBin(dir.path() / "velodyne" / "000000.bin", test::RandomCloud(5, 1));
    WriteKittiPoses(dir / "poses.txt", LinePoses(2));
    EXPECT_NE(ErrorOf(dir.path()).find("has 1 scans but 2 poses"), std::string::npos);
}

TEST(Dataset, UndetectableFolderSaysWhatWasLookedFor) {
    test::TempDir dir;
    test::WriteFile(dir / "notes.md", "nothing here");
    const std::string message = ErrorOf(dir.path());
    EXPECT_NE(message.find("cannot tell the dataset format"), std::string::npos) << message;
    EXPECT_NE(message.find("velodyne/*.bin"), std::string::npos) << message;
}

TEST(Dataset, MissingPathFileAndEmptyForcedFormatAreErrors) {
    test::TempDir dir;
    EXPECT_NE(ErrorOf(dir / "nope").find("no such dataset folder"), std::string::npos);
    test::WriteFile(dir / "file.bin", "");
    EXPECT_NE(ErrorOf(dir / "file.bin").find("is a file"), std::string::npos);
    DatasetOptions kitti;
    kitti.format = DatasetFormat::kKitti;
    EXPECT_NE(ErrorOf(dir.path(), kitti).find("holds no scans of the kitti layout"),
              std::string::npos);
}

TEST(Dataset, UnknownPoseFormatNamesTheLine) {
    test::TempDir dir;
    WritePcd(dir / "a.pcd", test::RandomCloud(5, 1), PcdEncoding::kAscii);
    test::WriteFile(dir / "traj.csv", "# comment\n1 2 3 4\n");
    DatasetOptions options;
    options.poses_file = dir / "traj.csv";
    const std::string message = ErrorOf(dir.path(), options);
    EXPECT_NE(message.find("line 2: cannot tell the pose format"), std::string::npos) << message;
}

}  // namespace
}  // namespace lidarloop::io

#include <cmath>
#include <initializer_list>
#include <string>

#include <gtest/gtest.h>

#include "lidarloop/core/min_gap.hpp"
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
    WriteKittiBin(dir.path() / "velodyne" / "000001.bin", test::RandomCloud(5, 2));
    WriteKittiPoses(dir / "poses.txt", LinePoses(1));
    EXPECT_NE(ErrorOf(dir.path()).find("has 2 scans but 1 poses"), std::string::npos);
    // More poses than scans: frames are picked by number in KITTI layout alone.
    test::TempDir folder;
    WriteKittiBin(folder / "000000.bin", test::RandomCloud(5, 1));
    WriteKittiPoses(folder / "poses.txt", LinePoses(2));
    EXPECT_NE(ErrorOf(folder.path()).find("has 1 scans but 2 poses"), std::string::npos);
    // Frames 0 and 1 are a whole sequence's first: a third pose is an error, not ignored.
    WriteKittiPoses(dir / "poses.txt", LinePoses(3));
    EXPECT_NE(ErrorOf(dir.path())
                  .find("has 2 scans but 3 poses (the scans are frames 0 to 1: "
                        "their poses file holds one pose a scan)"),
              std::string::npos)
        << ErrorOf(dir.path());
    fs::rename(dir / "velodyne" / "000001.bin", dir / "velodyne" / "last.bin");
    EXPECT_NE(ErrorOf(dir.path())
                  .find("has 2 scans but 3 poses (poses are taken by frame number "
                        "only when every scan is named by one, and last.bin is "
                        "not)"),
              std::string::npos)
        << ErrorOf(dir.path());
}

// A KITTI layout of small scans named as the given frames: DIR/velodyne/FRAME.bin.
void WriteKittiFrames(const fs::path& dir, std::initializer_list<const char*> frames) {
    fs::create_directories(dir / "velodyne");
    for (const char* frame : frames)
        WriteKittiBin(dir / "velodyne" / (std::string(frame) + ".bin"), test::RandomCloud(5, 1));
}

// A zigzag: every step is sqrt(2) m long, so a path differs from the straight line between
// frames.
std::vector<core::StampedPose> ZigzagPoses(std::size_t count) {
    std::vector<core::StampedPose> poses(count);
    for (std::size_t i = 0; i < count; ++i) {
        poses[i].T_world_sensor.translation() =
            Eigen::Vector3d(static_cast<double>(i), static_cast<double>(i % 2), 0.0);
    }
    return poses;
}

TEST(Dataset, KittiFramesTakeTheirPosesAndPathFromTheWholeSequence) {
    test::TempDir dir;
    WriteKittiFrames(dir.path(), {"000001", "000004", "000005"});
    WriteKittiPoses(dir / "poses.txt", ZigzagPoses(8));
    test::WriteFile(dir / "times.txt", "0\n0.1\n0.2\n0.3\n0.4\n0.5\n0.6\n0.7\n");
    const Dataset dataset = OpenDataset(dir.path());
    ASSERT_EQ(dataset.poses().size(), 3U);
    EXPECT_NEAR(dataset.poses()[1].T_world_sensor.translation().x(), 4.0, 1e-12);
    EXPECT_NEAR(dataset.poses()[2].T_world_sensor.translation().y(), 1.0, 1e-12);
    EXPECT_NEAR(dataset.ScanTime(1), 0.4, 1e-12);
    const std::vector<double> path_m = core::CumulativePathM(dataset.poses());
    ASSERT_EQ(path_m.size(), 3U);
    EXPECT_NEAR(path_m[0], 0.0, 1e-12);
    EXPECT_NEAR(path_m[1], 3.0 * std::sqrt(2.0), 1e-12);  // the straight line is sqrt(10)
    EXPECT_NEAR(path_m[2], 4.0 * std::sqrt(2.0), 1e-12);
    EXPECT_NE(FramesNote(dataset.ScanPaths(), dataset.poses(), "poses")
                  .find("the 3 scans are frames of a KITTI drive (1 to 5, by their file names)"),
              std::string::npos);
    EXPECT_EQ(FramesNote(dataset.ScanPaths(), ZigzagPoses(3), "odometry"), "");

    WriteKittiBin(dir / "velodyne" / "000009.bin", test::RandomCloud(5, 1));
    EXPECT_NE(ErrorOf(dir.path())
                  .find("poses.txt: holds 8 poses (frames 0 to 7) but scan "
                        "000009.bin is frame 9"),
              std::string::npos)
        << ErrorOf(dir.path());
    fs::remove(dir / "velodyne" / "000009.bin");
    WriteKittiBin(dir / "velodyne" / "4.bin", test::RandomCloud(5, 1));
    EXPECT_NE(ErrorOf(dir.path()).find("000004.bin: is frame 4, as is 4.bin"), std::string::npos)
        << ErrorOf(dir.path());
    fs::remove(dir / "velodyne" / "4.bin");
    // KITTI-360's ten digits, and a number beyond any drive.
    fs::rename(dir / "velodyne" / "000005.bin", dir / "velodyne" / "0000000005.bin");
    EXPECT_EQ(OpenDataset(dir.path()).poses().size(), 3U);
    WriteKittiBin(dir / "velodyne" / "123456789012.bin", test::RandomCloud(5, 1));
    EXPECT_NE(ErrorOf(dir.path()).find("scan 123456789012.bin is a later frame"), std::string::npos)
        << ErrorOf(dir.path());
}

// KITTI's test sequences have times but no poses: a gap in seconds needs no poses. Some frames
// take their frames' times; a folder's times.txt holds one a scan.
TEST(Dataset, TimesWithoutPosesAreTheScansTimes) {
    test::TempDir dir;
    WriteKittiFrames(dir.path(), {"000000", "000001", "000002"});
    test::WriteFile(dir / "times.txt", "0.5\n0.6\n0.75\n");
    Dataset dataset = OpenDataset(dir.path());
    EXPECT_FALSE(dataset.HasPoses());
    ASSERT_TRUE(dataset.HasTimes());
    EXPECT_EQ(dataset.ScanTime(2), 0.75);
    test::WriteFile(dir / "times.txt", "0.5\n0.6\n0.75\n0.9\n1.0\n");
    EXPECT_NE(ErrorOf(dir.path()).find("times.txt: holds 5 times for 3 scans"), std::string::npos)
        << ErrorOf(dir.path());
    fs::rename(dir / "velodyne" / "000002.bin", dir / "velodyne" / "000004.bin");
    dataset = OpenDataset(dir.path());
    EXPECT_EQ(dataset.ScanTime(2), 1.0);  // frame 4
    test::WriteFile(dir / "times.txt", "0.5\n0.6\n0.5\n");
    EXPECT_NE(ErrorOf(dir.path()).find("times.txt: line 3: time 0.5 goes back"), std::string::npos)
        << ErrorOf(dir.path());

    test::TempDir folder;
    WriteKittiBin(folder / "a.bin", test::RandomCloud(5, 1));
    WriteKittiBin(folder / "b.bin", test::RandomCloud(5, 2));
    test::WriteFile(folder / "times.txt", "3\n4\n");
    EXPECT_EQ(OpenDataset(folder.path()).ScanTime(1), 4.0);
    test::WriteFile(folder / "times.txt", "3\n");
    EXPECT_NE(ErrorOf(folder.path()).find("holds 1 times for 2 scans"), std::string::npos);
}

// A TUM file's rows are times, not frames: one with more rows than scans is no list of frames.
TEST(Dataset, TumPosesAreNotPickedByFrameNumber) {
    test::TempDir dir;
    WriteKittiFrames(dir.path(), {"000001", "000004"});
    WriteTumPoses(dir / "poses.txt", LinePoses(8));
    EXPECT_NE(ErrorOf(dir.path())
                  .find("has 2 scans but 8 poses (a TUM file's rows are times, "
                        "not frames"),
              std::string::npos)
        << ErrorOf(dir.path());
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

// An empty poses file, given or in the folder, is an error naming it, not "no poses" (a given
// one would otherwise hide the folder's poses.txt).
TEST(Dataset, APosesFileWithoutPosesIsAnError) {
    test::TempDir dir;
    fs::create_directories(dir / "velodyne");
    WriteKittiBin(dir / "velodyne" / "000000.bin", test::RandomCloud(5, 1));
    WriteKittiPoses(dir / "poses.txt", LinePoses(1));
    test::WriteFile(dir / "empty.txt", "# only a comment\n\n");
    DatasetOptions given;
    given.poses_file = dir / "empty.txt";
    EXPECT_NE(ErrorOf(dir.path(), given).find("empty.txt: holds no poses"), std::string::npos)
        << ErrorOf(dir.path(), given);
    test::WriteFile(dir / "poses.txt", "");
    EXPECT_NE(ErrorOf(dir.path()).find("poses.txt: holds no poses"), std::string::npos)
        << ErrorOf(dir.path());
    test::TempDir folder;
    WriteKittiBin(folder / "000000.bin", test::RandomCloud(5, 1));
    test::WriteFile(folder / "poses.txt", "");
    EXPECT_NE(ErrorOf(folder.path()).find("holds no poses"), std::string::npos);
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

// The real KITTI 08 samples with the official poses and calibration (known answers: the
// relative poses of the samples' README, from Tr^-1 P_i Tr); skipped when the folder is absent.
TEST(Dataset, RealKittiFramesTakeTheOfficialPoses) {
    const fs::path samples = LIDARLOOP_KITTI_SAMPLES_DIR;
    if (!fs::exists(samples / "08" / "velodyne"))
        GTEST_SKIP() << "real KITTI samples not found at " << samples;
    DatasetOptions options;
    options.poses_file = samples / "poses" / "08.txt";
    options.calib_file = samples / "calib_08.txt";
    const Dataset dataset = OpenDataset(samples / "08", options);
    ASSERT_EQ(dataset.poses().size(), 4U);  // frames 209, 720, 1500, 1684 of 4,071
    EXPECT_EQ(dataset.ScanTime(3), 1684.0);
    const auto relative = [&](std::size_t a, std::size_t b) {
        return dataset.poses()[a].T_world_sensor.inverse() * dataset.poses()[b].T_world_sensor;
    };
    const auto yaw_deg = [](const core::Transform& T) {
        return std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * 180.0 / M_PI;
    };
    const core::Transform T_209_1684 = relative(0, 3);
    EXPECT_TRUE(T_209_1684.translation().isApprox(Eigen::Vector3d(-0.677, -1.617, -2.691), 1e-3))
        << T_209_1684.translation().transpose();
    EXPECT_NEAR(yaw_deg(T_209_1684), -175.2, 0.05);
    const core::Transform T_720_1500 = relative(1, 2);
    EXPECT_TRUE(T_720_1500.translation().isApprox(Eigen::Vector3d(-2.084, -2.026, -1.057), 1e-3))
        << T_720_1500.translation().transpose();
    EXPECT_NEAR(yaw_deg(T_720_1500), -148.5, 0.05);
}

}  // namespace
}  // namespace lidarloop::io

// detect on real KITTI HDL-64E frames with the official poses (../shared/data/kitti-samples, never
// copied into the repository; skipped with a message when absent, as in CI). Ground truth and how
// far to trust it at the 08 loops: the folder's README.md.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "lidarloop/app/detection.hpp"
#include "lidarloop/io/dataset.hpp"
#include "test_utils.hpp"

namespace lidarloop {
namespace {

const std::filesystem::path kSamples = LIDARLOOP_KITTI_SAMPLES_DIR;

double YawDeg(const core::Transform& T) {
    return std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * 180.0 / M_PI;
}

// The samples' frames of sequence 08 with the drive's official poses, converted by its calib.
io::Dataset Sequence08() {
    io::DatasetOptions options;
    options.poses_file = kSamples / "poses" / "08.txt";
    options.calib_file = kSamples / "calib_08.txt";
    return io::OpenDataset(kSamples / "08", options);
}

// Frames 209, 720, 1500, 1684 of sequence 08 with its 4,071 poses: the path between the frames
// is the drive's (hundreds of metres), so both reverse revisits pass the 50 m path rule, and
// verification closes them at the README's yaw (within 2 degrees) and planar translation
// (within 1.5 m; the ground truth drifts between the visits).
TEST(KittiSamplesRun, DetectClosesBothLoopsOfSequence08WithTheOfficialPoses) {
    if (!std::filesystem::exists(kSamples / "08" / "velodyne"))
        GTEST_SKIP() << "real KITTI samples not found at " << kSamples;
    const io::Dataset dataset = Sequence08();
    test::TempDir dir;
    app::DetectRequest request;
    request.config.detection.min_gap.value = 0;  // four frames: the path rule decides
    request.out = dir / "detect";
    const app::DetectOutcome outcome = app::RunDetect(dataset, request);
    ASSERT_EQ(outcome.path_m.size(), 4U);
    EXPECT_GT(outcome.path_m[2] - outcome.path_m[1], 400.0);  // the straight line: 3 m
    ASSERT_FALSE(outcome.notes.empty());
    EXPECT_EQ(outcome.notes[0],
              "the 4 scans are frames of a KITTI drive (209 to 1684, by their file names): they "
              "take those frames' poses, and the path between them is the drive's");
    // Frames picked from a drive do not follow one another: no registration of a scan to the
    // one before places submaps (1500 after 720 is a loop, not a step).
    ASSERT_EQ(outcome.notes.size(), 2U);
    EXPECT_TRUE(outcome.notes[1].starts_with("no submaps")) << outcome.notes[1];

    struct Expected {
        std::size_t query, match;
        Eigen::Vector2d xy_m;
        double yaw_deg;
    };
    for (const Expected& loop :
         {Expected{2, 1, {-2.084, -2.026}, -148.5}, Expected{3, 0, {-0.677, -1.617}, -175.2}}) {
        const pipeline::LoopQuery& query = outcome.queries.at(loop.query);
        const std::optional<std::size_t> found = query.loop();
        ASSERT_TRUE(found) << "query " << loop.query;
        EXPECT_EQ(query.candidates[*found].index, loop.match);
        const core::Transform& T = query.verifications[*found].T_match_query;
        EXPECT_LT((T.translation().head<2>() - loop.xy_m).norm(), 1.5) << T.translation();
        EXPECT_NEAR(YawDeg(T), loop.yaw_deg, 2.0);
    }
    EXPECT_FALSE(outcome.queries.at(1).loop());  // 720 is 93 m from 209
    EXPECT_EQ(outcome.accepted, 2U);
}

// KITTI's official poses are in its camera frame. Given as odometry without their calib, the
// odometry's gate judges LiDAR-frame loops against camera-frame turns and rejects both true
// loops, and the run says why; with --odometry-calib both are closed.
TEST(KittiSamplesRun, OfficialPosesAsOdometryNeedTheirCalib) {
    if (!std::filesystem::exists(kSamples / "08" / "velodyne"))
        GTEST_SKIP() << "real KITTI samples not found at " << kSamples;
    const io::Dataset dataset = Sequence08();
    test::TempDir dir;
    app::DetectRequest request;
    request.config.detection.min_gap.value = 0;
    request.odometry_file = kSamples / "poses" / "08.txt";
    request.out = dir / "uncalibrated";
    const app::DetectOutcome uncalibrated = app::RunDetect(dataset, request);
    EXPECT_EQ(uncalibrated.accepted, 0U);
    EXPECT_EQ(std::count_if(uncalibrated.notes.begin(), uncalibrated.notes.end(),
                            [](const std::string& note) {
                                return note.find("--odometry-calib") != std::string::npos;
                            }),
              1);
    request.odometry_calib = kSamples / "calib_08.txt";
    request.out = dir / "calibrated";
    const app::DetectOutcome calibrated = app::RunDetect(dataset, request);
    EXPECT_EQ(calibrated.accepted, 2U);
    for (const std::string& note : calibrated.notes)
        EXPECT_EQ(note.find("--odometry-calib"), std::string::npos) << note;
}

}  // namespace
}  // namespace lidarloop

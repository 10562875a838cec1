// The optimise run: it detects (or reads) the loops, shrinks the odometry's error, writes the
// results folder, and names the file and line of bad input.
#include <algorithm>
#include <fstream>
#include <limits>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app_test_utils.hpp"
#include "lidarloop/app/optimisation.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/io/read_error.hpp"
#include "test_utils.hpp"

namespace lidarloop {
namespace {

// A query whose candidates were verified: `accepted_overlaps[c]` < 0 means rejected.
pipeline::LoopQuery VerifiedQuery(const std::vector<std::size_t>& matches,
                                  const std::vector<double>& accepted_overlaps) {
    pipeline::LoopQuery query;
    query.query = 99;
    for (std::size_t c = 0; c < matches.size(); ++c) {
        query.candidates.push_back({matches[c], 0.1 * static_cast<double>(c)});
        registration::Verification verdict;
        verdict.accepted = accepted_overlaps[c] >= 0.0;
        verdict.overlap.query_fraction = verdict.overlap.match_fraction =
            std::max(accepted_overlaps[c], 0.0);
        query.verifications.push_back(verdict);
    }
    query.accepted = query.loop().has_value();
    return query;
}

TEST(LoopsForPoseGraph, TheLoopThenEarlierPassesFarApartInPath) {
    std::vector<double> path_m(100);
    for (std::size_t i = 0; i < path_m.size(); ++i) path_m[i] = 2.0 * static_cast<double>(i);
    // Matches at 20, 22 (4 m of path from 20), 50 (60 m), 51, 80 (120 m), 81; 51 rejected.
    const pipeline::LoopQuery query =
        VerifiedQuery({20, 22, 50, 51, 80, 81}, {0.5, 0.7, 0.4, -1.0, 0.45, 0.6});
    posegraph::PoseGraphConfig config;
    ASSERT_EQ(config.max_loops_per_scan, 3);
    ASSERT_EQ(config.min_loop_separation_m, 50.0);
    // The loop (22, overlap 0.7), then 81 (0.6; 118 m from 22), then 50 (0.4): 20 lies 4 m
    // from 22, 80 2 m from 81.
    EXPECT_EQ(app::LoopsForPoseGraph(query, path_m, config), (std::vector<std::size_t>{1, 5, 2}));
    config.max_loops_per_scan = 2;
    EXPECT_EQ(app::LoopsForPoseGraph(query, path_m, config), (std::vector<std::size_t>{1, 5}));
    config.max_loops_per_scan = 1;
    EXPECT_EQ(app::LoopsForPoseGraph(query, path_m, config), (std::vector<std::size_t>{1}));
    config.max_loops_per_scan = 10;
    config.min_loop_separation_m = 1.0;
    EXPECT_EQ(app::LoopsForPoseGraph(query, path_m, config),
              (std::vector<std::size_t>{1, 5, 0, 4, 2}));
    EXPECT_EQ(app::LoopsForPoseGraph(query, {}, config), (std::vector<std::size_t>{1}));
    EXPECT_TRUE(
        app::LoopsForPoseGraph(VerifiedQuery({20, 50}, {-1.0, -1.0}), path_m, config).empty());
    EXPECT_TRUE(app::LoopsForPoseGraph(pipeline::LoopQuery{}, path_m, config).empty());
}

// Verifying up to the first loop, optimise goes on only to the candidates that may add a loop
// LoopsForPoseGraph takes: far in path from every accepted match, while there are fewer than
// max_loops_per_scan.
TEST(PoseGraphLoopsWanted, OnlyCandidatesFarInPathFromEveryLoopWhileThereIsRoom) {
    std::vector<double> path_m(100);
    for (std::size_t i = 0; i < path_m.size(); ++i) path_m[i] = 2.0 * static_cast<double>(i);
    // Matches at 20 (accepted), 22 (4 m of path from 20), 50 (60 m), 80 (120 m).
    pipeline::LoopQuery query = VerifiedQuery({20, 22, 50, 80}, {0.5, -1.0, -1.0, -1.0});
    posegraph::PoseGraphConfig config;
    const pipeline::MoreLoopsWanted wanted = app::PoseGraphLoopsWanted(path_m, config);
    EXPECT_FALSE(wanted(query, 1));
    EXPECT_TRUE(wanted(query, 2));
    EXPECT_TRUE(wanted(query, 3));
    query.verifications[2].accepted = true;  // 50 accepted: 80 is 60 m from it
    EXPECT_TRUE(wanted(query, 3));
    config.max_loops_per_scan = 2;  // two loops taken: no room
    EXPECT_FALSE(app::PoseGraphLoopsWanted(path_m, config)(query, 3));
    config.max_loops_per_scan = 3;
    config.min_loop_separation_m = 70.0;  // 80 lies 60 m from 50
    EXPECT_FALSE(app::PoseGraphLoopsWanted(path_m, config)(query, 3));
    EXPECT_FALSE(static_cast<bool>(app::PoseGraphLoopsWanted({}, config)));  // no path: the loop
    path_m[80] = std::numeric_limits<double>::quiet_NaN();  // LoopsForPoseGraph would not take it
    config.min_loop_separation_m = 50.0;
    EXPECT_FALSE(app::PoseGraphLoopsWanted(path_m, config)(query, 3));
}

class OptimisationRun : public ::testing::Test {
protected:
    void SetUp() override { dataset_.emplace(test::SmallSequence(dir_ / "sequence")); }
    app::OptimiseRequest Request(const std::string& out) const {
        app::OptimiseRequest request;
        request.odometry_file = dir_ / "sequence" / "poses_odometry.txt";
        request.config.detection.min_gap.value = 10;
        request.config.detection.top_k = 1;  // one candidate to verify per scan: faster
        request.out = dir_ / out;
        return request;
    }

    test::TempDir dir_;
    std::optional<io::Dataset> dataset_;
};

TEST_F(OptimisationRun, DetectsLoopsAndShrinksTheError) {
    // A verified detection and two optimisations; the graph of loops runs under the sanitizers
    // in DuplicateLoopsAreMergedWithANote, detection in DetectionRun.
    LIDARLOOP_RELEASE_SUITE_ONLY();
    app::OptimiseRequest request = Request("optimised");
    request.format = app::PoseFormat::kTum;
    const app::OptimiseOutcome outcome = app::RunOptimisation(*dataset_, request);
    ASSERT_GE(outcome.result.loops_used, 8u);  // 10 with loops no farther apart than 10 m
    ASSERT_TRUE(outcome.odometry && outcome.optimised);
    EXPECT_LT(outcome.optimised->ate_rmse_m, outcome.odometry->ate_rmse_m / 2.0)
        << outcome.odometry->ate_rmse_m << " -> " << outcome.optimised->ate_rmse_m;
    const auto out = request.out;
    for (const char* file : {"poses_optimised.txt", "graph.g2o", "loop_verdicts.csv",
                             "metrics.json", "report.md", "config.yaml", "detection/loops.csv"}) {
        EXPECT_TRUE(std::filesystem::exists(out / file)) << file;
    }
    const auto poses = io::ReadTumPoses(out / "poses_optimised.txt");
    ASSERT_EQ(poses.size(), dataset_->size());
    EXPECT_TRUE(poses.back().T_world_sensor.isApprox(outcome.result.poses.back(), 1e-12));
    std::ifstream in(out / "metrics.json");
    const nlohmann::json metrics = nlohmann::json::parse(in);
    EXPECT_DOUBLE_EQ(metrics["ate_rmse_m_optimised"].get<double>(), outcome.optimised->ate_rmse_m);
    EXPECT_EQ(metrics["loops"]["used"].get<std::size_t>(), outcome.result.loops_used);
    EXPECT_TRUE(metrics["rpe_optimised"].contains("rpe_translation_percent"));

    // The loops detect wrote, read back: the same graph, the same result.
    app::OptimiseRequest again = Request("from_file");
    again.loops_file = out / "detection" / "loops.csv";
    const app::OptimiseOutcome read = app::RunOptimisation(*dataset_, again);
    ASSERT_EQ(read.loops.size(), outcome.loops.size());
    EXPECT_NEAR(read.optimised->ate_rmse_m, outcome.optimised->ate_rmse_m, 1e-3);
}

TEST_F(OptimisationRun, WithoutLoopsTheOdometryComesBackWithANote) {
    test::WriteFile(dir_ / "none.csv",
                    "query,match,distance,second_ratio,accepted,rank,tx,ty,tz,qx,qy,qz,qw\n"
                    "50,3,0.1,,0,1,0,0,0,0,0,0,1\n");
    app::OptimiseRequest request = Request("none");
    request.loops_file = dir_ / "none.csv";
    request.format = app::PoseFormat::kTum;
    const app::OptimiseOutcome outcome = app::RunOptimisation(*dataset_, request);
    ASSERT_FALSE(outcome.notes.empty());
    EXPECT_TRUE(test::Contains(outcome.notes.front(), "no loop"));
    EXPECT_DOUBLE_EQ(outcome.optimised->ate_rmse_m, outcome.odometry->ate_rmse_m);
    // A KITTI odometry file has no times: TUM poses carry the scans' own, not their numbers.
    const auto poses = io::ReadTumPoses(request.out / "poses_optimised.txt");
    ASSERT_EQ(poses.size(), dataset_->size());
    ASSERT_NE(dataset_->ScanTime(5), 5.0);
    for (const std::size_t i : {std::size_t{0}, std::size_t{5}, dataset_->size() - 1})
        EXPECT_NEAR(poses[i].time_s, dataset_->ScanTime(i), 1e-6) << i;
}

// The pose graph needs the loops' poses: detecting without verification is refused, not run
// with verification behind the user's back (as --no-verify once was); loops from a file need none.
TEST_F(OptimisationRun, DetectingWithoutVerificationIsRefused) {
    app::OptimiseRequest request = Request("unverified");
    request.config.detection.verify = false;
    EXPECT_THROW(app::RunOptimisation(*dataset_, request), core::ConfigError);
    EXPECT_FALSE(std::filesystem::exists(dir_ / "unverified" / "detection"));
    test::WriteFile(dir_ / "loops.csv",
                    "query,match,distance,second_ratio,accepted,rank,tx,ty,tz,qx,qy,qz,qw\n");
    request.loops_file = dir_ / "loops.csv";
    EXPECT_NO_THROW(app::RunOptimisation(*dataset_, request));
}

// A loop repeated in loops.csv, also with its two scans swapped, enters the graph once, with a
// note (issue 25, item 4).
TEST_F(OptimisationRun, DuplicateLoopsAreMergedWithANote) {
    const std::string header =
        "query,match,distance,second_ratio,accepted,rank,tx,ty,tz,qx,qy,qz,qw\n";
    test::WriteFile(dir_ / "loops.csv",
                    header + "150,30,0.1,,1,1,1,2,0,0,0,0,1\n" + "150,30,0.1,,1,1,1,2,0,0,0,0,1\n" +
                        "30,150,0.1,,1,1,-1,-2,0,0,0,0,1\n" + "160,40,0.1,,1,1,0,0,0,0,0,0,1\n" +
                        "150,30,0.1,,1,1,5,5,0,0,0,0,1\n");
    app::OptimiseRequest request = Request("merged");
    request.loops_file = dir_ / "loops.csv";
    const app::OptimiseOutcome outcome = app::RunOptimisation(*dataset_, request);
    ASSERT_EQ(outcome.loops.size(), 2u);
    EXPECT_EQ(outcome.loops[0].query, 150u);
    EXPECT_DOUBLE_EQ(outcome.loops[0].T_match_query.translation().x(), 1.0);  // the first row
    EXPECT_EQ(outcome.loops[1].query, 160u);
    EXPECT_EQ(outcome.result.loops.size(), 2u);
    bool noted = false;
    for (const std::string& note : outcome.notes) {
        if (test::Contains(note, "3 duplicate rows of loops.csv merged"))
            noted = test::Contains(note, "lines 3, 4, 6)");
    }
    EXPECT_TRUE(noted) << ::testing::PrintToString(outcome.notes);
}

// Odometry that jumps farther than any vehicle moves between two scans is an error naming the
// line (issue 25, item 8).
TEST_F(OptimisationRun, OdometryThatJumpsNamesTheLine) {
    auto odometry = io::ReadKittiPoses(dir_ / "sequence" / "poses_odometry.txt");
    for (std::size_t i = 120; i < odometry.size(); ++i) {
        odometry[i].T_world_sensor.translation().x() += 500.0;  // a reset to a far origin
    }
    io::WriteKittiPoses(dir_ / "jump.txt", odometry);
    app::OptimiseRequest request = Request("jump");
    request.odometry_file = dir_ / "jump.txt";
    try {
        app::RunOptimisation(*dataset_, request);
        FAIL() << "no error";
    } catch (const io::ReadError& e) {
        EXPECT_TRUE(test::Contains(e.what(), "jump.txt: line 121: the pose is ")) << e.what();
    }
}

TEST_F(OptimisationRun, BadInputNamesTheFileAndLine) {
    const auto odometry = io::ReadKittiPoses(dir_ / "sequence" / "poses_odometry.txt");
    io::WriteKittiPoses(dir_ / "short.txt",
                        std::vector<core::StampedPose>(odometry.begin(), odometry.end() - 1));
    app::OptimiseRequest request = Request("bad");
    request.odometry_file = dir_ / "short.txt";
    try {
        app::RunOptimisation(*dataset_, request);
        FAIL() << "no error";
    } catch (const io::ReadError& e) {
        EXPECT_TRUE(test::Contains(e.what(), "short.txt: holds 199 poses but"));
    }
    test::WriteFile(dir_ / "loops.csv",
                    "query,match,distance,second_ratio,accepted,rank,tx,ty,tz,qx,qy,qz,qw\n"
                    "50,3,0.1,,1,1,0,0,0,0,0,0,1\n"
                    "250,3,0.1,,1,1,0,0,0,0,0,0,1\n");
    request = Request("bad");
    request.loops_file = dir_ / "loops.csv";
    try {
        app::RunOptimisation(*dataset_, request);
        FAIL() << "no error";
    } catch (const io::ReadError& e) {
        EXPECT_TRUE(test::Contains(e.what(), "loops.csv: line 3: query scan 250 does not exist"));
    }
}

}  // namespace
}  // namespace lidarloop

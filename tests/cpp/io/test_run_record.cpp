// run.json, the proof that lidarloop wrote a folder: read back, and an unfinished sequence
// refused by the dataset reader (issue 25, item 6).
#include <string>

#include <gtest/gtest.h>

#include "lidarloop/io/dataset.hpp"
#include "lidarloop/io/kitti_bin.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/run_record.hpp"
#include "test_utils.hpp"

namespace lidarloop::io {
namespace fs = std::filesystem;
namespace {

void WriteScans(const fs::path& folder, int count) {
    fs::create_directories(folder / "velodyne");
    for (int i = 0; i < count; ++i) {
        WriteKittiBin(folder / "velodyne" / ("00000" + std::to_string(i) + ".bin"),
                      test::RandomCloud(20, static_cast<unsigned>(i)));
    }
}

TEST(RunRecord, ReadsWhatLidarloopWroteAndIgnoresOtherFiles) {
    test::TempDir dir;
    EXPECT_FALSE(ReadRunRecord(dir.path()));
    test::WriteFile(dir / "run.json", R"({"tool": "other", "files": ["a"]})");
    EXPECT_FALSE(ReadRunRecord(dir.path()));
    test::WriteFile(dir / "run.json", "{not json");
    EXPECT_FALSE(ReadRunRecord(dir.path()));
    test::WriteFile(dir / "run.json", R"({"tool": "lidarloop", "status": "complete",
        "files": ["loops.csv", "../escape", "/abs", 3]})");
    const auto results = ReadRunRecord(dir.path());
    ASSERT_TRUE(results);
    EXPECT_EQ(results->kind, RunKind::kResults);  // run.json before kinds existed
    EXPECT_EQ(results->files, std::vector<std::string>{"loops.csv"});
    test::WriteFile(dir / "run.json", R"({"tool": "lidarloop", "kind": "dataset",
        "status": "interrupted", "files": []})");
    EXPECT_EQ(ReadRunRecord(dir.path())->kind, RunKind::kDataset);
}

// simulate wrote no run.json before; its simulation.yaml is the proof.
TEST(RunRecord, ASequenceFromBeforeRunJsonIsACompleteDataset) {
    test::TempDir dir;
    test::WriteFile(dir / "simulation.yaml", "# lidarloop 0.1.0 simulate: the parameters\n");
    const auto record = ReadRunRecord(dir.path());
    ASSERT_TRUE(record);
    EXPECT_EQ(record->kind, RunKind::kDataset);
    EXPECT_EQ(record->status, "complete");
    test::WriteFile(dir / "simulation.yaml", "scene: urban\n");  // anybody's
    EXPECT_FALSE(ReadRunRecord(dir.path()));
}

TEST(RunRecord, AnUnfinishedSequenceIsRefusedByTheReader) {
    test::TempDir dir;
    WriteScans(dir.path(), 3);
    EXPECT_EQ(OpenDataset(dir.path()).size(), 3U);
    for (const std::string status : {"interrupted", "failed"}) {
        test::WriteFile(dir / "run.json",
                        R"({"tool": "lidarloop", "kind": "dataset", "status": ")" + status +
                            R"(", "files": []})");
        try {
            OpenDataset(dir.path());
            FAIL() << "an unfinished sequence was opened";
        } catch (const ReadError& e) {
            EXPECT_NE(std::string(e.what()).find("not finished"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(status), std::string::npos) << e.what();
        }
    }
    // A results folder's run.json says nothing about scans beside it.
    test::WriteFile(dir / "run.json",
                    R"({"tool": "lidarloop", "kind": "results", "status": "failed"})");
    EXPECT_EQ(OpenDataset(dir.path()).size(), 3U);
}

}  // namespace
}  // namespace lidarloop::io

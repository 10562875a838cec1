// Results folders that never lie: staged files appear only when the run completes, run.json is
// written last and says how the run ended, earlier runs leave nothing behind, folders of other
// files and folders inside the dataset are refused, and a full disk is an error.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/app/run_folder.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/read_error.hpp"
#include "test_utils.hpp"

namespace lidarloop::app {
namespace {

namespace fs = std::filesystem;

nlohmann::json Manifest(const fs::path& folder) {
    std::ifstream in(folder / "run.json");
    return nlohmann::json::parse(in);
}

std::vector<std::string> Entries(const fs::path& folder) {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(folder))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

TEST(RunFolder, FilesAppearOnlyWhenTheRunCompletesAndRunJsonSaysSo) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    {
        RunFolder folder(out, {"lidarloop detect x --out results", dir / "dataset", false});
        test::WriteFile(folder.staging() / "loops.csv", "query,match\n");
        test::WriteFile(folder.staging() / "b.txt", "b");
        EXPECT_FALSE(fs::exists(out / "loops.csv"));  // still staged
        EXPECT_FALSE(fs::exists(out / "run.json"));
        EXPECT_EQ(folder.Complete(), (std::vector<std::string>{"b.txt", "loops.csv"}));
    }
    EXPECT_EQ(Entries(out), (std::vector<std::string>{"b.txt", "loops.csv", "run.json"}));
    const nlohmann::json manifest = Manifest(out);
    EXPECT_EQ(manifest["status"], "complete");
    EXPECT_EQ(manifest["tool"], "lidarloop");
    EXPECT_EQ(manifest["command_line"], "lidarloop detect x --out results");
    EXPECT_EQ(manifest["files"], nlohmann::json({"b.txt", "loops.csv"}));
    EXPECT_FALSE(manifest["version"].get<std::string>().empty());
    EXPECT_FALSE(manifest["started"].get<std::string>().empty());
    EXPECT_FALSE(manifest["ended"].get<std::string>().empty());
}

TEST(RunFolder, AFailedOrInterruptedRunLeavesOnlyRunJson) {
    test::TempDir dir;
    for (const RunStatus status : {RunStatus::kFailed, RunStatus::kInterrupted}) {
        const fs::path out = dir / ToString(status);
        RunFolder folder(out, {});
        test::WriteFile(folder.staging() / "loops.csv", "half a fi");
        folder.Abandon(status, "disk full");
        EXPECT_EQ(Entries(out), std::vector<std::string>{"run.json"});
        EXPECT_EQ(Manifest(out)["status"], ToString(status));
        EXPECT_EQ(Manifest(out)["message"], "disk full");
        EXPECT_THROW(folder.Complete(), io::WriteError);  // the first decision stands
    }
    {
        RunFolder dropped(dir / "dropped", {});  // never completed: failed
    }
    EXPECT_EQ(Manifest(dir / "dropped")["status"], "failed");
}

TEST(RunFolder, TheFilesOfTheRunBeforeAreRemovedOthersRefused) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    {
        RunFolder first(out, {});
        test::WriteFile(first.staging() / "skipped.txt", "scan 3: bad");
        test::WriteFile(first.staging() / "loops.csv", "1");
        first.Complete();
    }
    test::WriteFile(out / "notes.md", "mine");  // the user's, not the run's
    {
        RunFolder second(out, {});
        EXPECT_EQ(Entries(out),
                  (std::vector<std::string>{".lidarloop-staging-" + std::to_string(::getpid()),
                                            "notes.md"}));
        test::WriteFile(second.staging() / "loops.csv", "2");
        second.Complete();
    }
    // No stale skipped.txt claims a skipped scan in the new run.
    EXPECT_EQ(Entries(out), (std::vector<std::string>{"loops.csv", "notes.md", "run.json"}));
    EXPECT_EQ(test::ReadFile(out / "loops.csv"), "2");

    const fs::path foreign = dir / "foreign";
    fs::create_directories(foreign);
    test::WriteFile(foreign / "thesis.tex", "x");
    try {
        RunFolder refused(foreign, {});
        FAIL() << "a folder of other files was accepted";
    } catch (const io::WriteError& e) {
        EXPECT_NE(std::string(e.what()).find("holds no lidarloop run.json"), std::string::npos)
            << e.what();
    }
    RunFolder allowed(foreign, {"", {}, /*overwrite=*/true});
    allowed.Complete();
    EXPECT_TRUE(fs::exists(foreign / "thesis.tex"));
}

// optimise writes a whole detect run into detection/: running it again into the same folder
// must replace that folder too, not fail after removing the rest.
TEST(RunFolder, AFolderOfTheRunBeforeIsReplaced) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    for (const std::string run : {"1", "2"}) {
        RunFolder folder(out, {});
        fs::create_directories(folder.staging() / "detection");
        test::WriteFile(folder.staging() / "detection" / "loops.csv", run);
        test::WriteFile(folder.staging() / "metrics.json", run);
        EXPECT_NO_THROW(folder.Complete());
    }
    EXPECT_EQ(Entries(out), (std::vector<std::string>{"detection", "metrics.json", "run.json"}));
    EXPECT_EQ(test::ReadFile(out / "detection" / "loops.csv"), "2");
    EXPECT_EQ(Manifest(out)["status"], "complete");
}

TEST(RunFolder, AFolderInsideTheDatasetIsRefused) {
    test::TempDir dir;
    fs::create_directories(dir / "dataset" / "velodyne");
    for (const fs::path& inside :
         {dir / "dataset", dir / "dataset" / "velodyne", dir / "dataset" / "velodyne" / "out",
          dir / "dataset" / "velodyne" / ".." / "results"}) {
        EXPECT_THROW(RunFolder(inside, {"", dir / "dataset", true}), io::WriteError) << inside;
    }
    EXPECT_NO_THROW(RunFolder(dir / "dataset_results", {"", dir / "dataset", false}));
    EXPECT_FALSE(fs::exists(dir / "dataset" / "velodyne" / "out"));
}

TEST(RunInFolder, ReturnsWhatTheRunReturnsAndLeavesOnlyRunJsonWhenItThrows) {
    test::TempDir dir;
    const int answer = RunInFolder(dir / "ok", {}, [](const fs::path& staging) {
        test::WriteFile(staging / "loops.csv", "1");
        return 42;
    });
    EXPECT_EQ(answer, 42);
    EXPECT_EQ(Entries(dir / "ok"), (std::vector<std::string>{"loops.csv", "run.json"}));
    EXPECT_EQ(Manifest(dir / "ok")["status"], "complete");

    EXPECT_THROW(RunInFolder(dir / "bad", {},
                             [](const fs::path& staging) -> int {
                                 test::WriteFile(staging / "loops.csv", "half");
                                 throw io::ReadError("scan.bin", "truncated");
                             }),
                 io::ReadError);
    EXPECT_EQ(Entries(dir / "bad"), std::vector<std::string>{"run.json"});
    EXPECT_EQ(Manifest(dir / "bad")["status"], "failed");
    EXPECT_EQ(Manifest(dir / "bad")["message"], "scan.bin: truncated");
}

// What the CLI's signal watcher does on Ctrl-C: the running folder is abandoned as interrupted,
// and the run cannot complete afterwards.
TEST(RunInFolder, AbandonActiveRunInterruptsTheRunningFolderOnly) {
    test::TempDir dir;
    EXPECT_EQ(AbandonActiveRun(RunStatus::kInterrupted, "no run"), fs::path());
    fs::path abandoned;
    EXPECT_THROW(RunInFolder(dir / "run", {},
                             [&](const fs::path& staging) {
                                 test::WriteFile(staging / "loops.csv", "1");
                                 abandoned = AbandonActiveRun(RunStatus::kInterrupted, "signal 2");
                                 return 0;
                             }),
                 io::WriteError);
    EXPECT_EQ(abandoned, dir / "run");
    EXPECT_EQ(Entries(dir / "run"), std::vector<std::string>{"run.json"});
    EXPECT_EQ(Manifest(dir / "run")["status"], "interrupted");
    EXPECT_EQ(Manifest(dir / "run")["message"], "signal 2");
    EXPECT_EQ(AbandonActiveRun(RunStatus::kInterrupted, "after"), fs::path());  // ended
}

// /dev/full takes the open and fails every write with ENOSPC, as a full disk does; the
// writers must say so instead of leaving a file that looks whole.
TEST(ResultWriters, AFullDiskIsAnError) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    const fs::path full = "/dev/full";
    EXPECT_THROW(WriteJson(full, nlohmann::json{{"a", 1}}), io::WriteError);
    EXPECT_THROW(WriteLoopsCsv(full, {}), io::WriteError);
    EXPECT_THROW(WriteCandidatesCsv(full, {}), io::WriteError);
    EXPECT_THROW(io::WriteConfigYaml(full, {}), io::WriteError);
}

}  // namespace
}  // namespace lidarloop::app

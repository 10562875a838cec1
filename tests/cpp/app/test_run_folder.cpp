// Results folders that never lie: staged files appear only when the run completes, run.json is
// written last and says how the run ended, earlier runs leave nothing behind, folders of other
// files and folders inside the dataset are refused, and a full disk is an error.
#include <unistd.h>

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
#include "lidarloop/io/run_record.hpp"
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

TEST(RunFolder, ACommandsRunInfoRecordsWhatItWasGiven) {
    const RunInfo info = CommandRunInfo("detect", "lidarloop detect seq", {"seq", "odo.txt"}, true);
    EXPECT_EQ(info.command, "detect");
    EXPECT_EQ(info.command_line, "lidarloop detect seq");
    EXPECT_EQ(info.inputs, (std::vector<fs::path>{"seq", "odo.txt"}));
    EXPECT_TRUE(info.overwrite);
    EXPECT_EQ(info.kind, io::RunKind::kResults);
    EXPECT_FALSE(CommandRunInfo("map", "lidarloop map", {}, false).overwrite);
}

TEST(ResultsFolder, CountsTheCandidatesRejectedForAReason) {
    std::vector<pipeline::LoopQuery> queries(3);
    const auto verdict = [](registration::RejectReason reason) {
        registration::Verification v;
        v.reason = reason;
        v.accepted = reason == registration::RejectReason::kNone;
        return v;
    };
    using R = registration::RejectReason;
    queries[0].verifications = {verdict(R::kUnlikeNeighbours), verdict(R::kNone)};
    queries[2].verifications = {verdict(R::kLowOverlap), verdict(R::kUnlikeNeighbours),
                                verdict(R::kUnlikeNeighbours)};
    EXPECT_EQ(CountRejected(queries, R::kUnlikeNeighbours), 3U);
    EXPECT_EQ(CountRejected(queries, R::kLowOverlap), 1U);
    EXPECT_EQ(CountRejected(queries, R::kOdometryMismatch), 0U);
    EXPECT_EQ(CountRejected({}, R::kUnlikeNeighbours), 0U);
}

TEST(RunFolder, FilesAppearOnlyWhenTheRunCompletesAndRunJsonSaysSo) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    {
        RunFolder folder(out, {"lidarloop detect x --out results", {dir / "dataset"}, false});
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
        // The earlier results stay until the new ones are complete.
        EXPECT_EQ(Entries(out),
                  (std::vector<std::string>{second.staging().filename().string(), "loops.csv",
                                            "notes.md", "run.json", "skipped.txt"}));
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
        EXPECT_THROW(RunFolder(inside, {"", {dir / "dataset"}, true}), io::WriteError) << inside;
    }
    EXPECT_NO_THROW(RunFolder(dir / "dataset_results", {"", {dir / "dataset"}, false}));
    EXPECT_FALSE(fs::exists(dir / "dataset" / "velodyne" / "out"));
}

// A detect folder (results) with its files, for the tests of reruns into it.
void WriteDetectResults(const fs::path& out) {
    RunInFolder(out, {}, [](const fs::path& staging) {
        test::WriteFile(staging / "loops.csv", "first");
        test::WriteFile(staging / "database.lldb", "map");
        return 0;
    });
}

// Issue 25 (3): a rerun that fails must not have removed the results it would have replaced.
TEST(RunFolder, AFailedOrInterruptedRerunLeavesTheEarlierResultsIntact) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    WriteDetectResults(out);
    const std::string manifest = test::ReadFile(out / "run.json");
    EXPECT_THROW(RunInFolder(out, {},
                             [](const fs::path& staging) -> int {
                                 test::WriteFile(staging / "loops.csv", "half");
                                 throw io::ReadError("scan7.bin", "truncated");
                             }),
                 io::ReadError);
    {
        RunFolder interrupted(out, {});
        test::WriteFile(interrupted.staging() / "loops.csv", "half");
        interrupted.Abandon(RunStatus::kInterrupted, "signal 2");
    }
    EXPECT_EQ(Entries(out), (std::vector<std::string>{"database.lldb", "loops.csv", "run.json"}));
    EXPECT_EQ(test::ReadFile(out / "loops.csv"), "first");
    EXPECT_EQ(test::ReadFile(out / "run.json"), manifest);
}

// Issue 25 (2): optimise --loops res/loops.csv --out res, evaluate --results res/loops.csv
// --out res and detect --map res/database.lldb --out res would replace their own input.
TEST(RunFolder, AFolderHoldingAnInputIsRefusedBeforeAnythingIsRemoved) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    WriteDetectResults(out);
    for (const fs::path& input : {out / "loops.csv", out / "database.lldb", out}) {
        for (const bool overwrite : {false, true}) {
            try {
                RunFolder refused(out, {"", {dir / "dataset", input}, overwrite});
                FAIL() << "a folder holding the input " << input << " was accepted";
            } catch (const io::WriteError& e) {
                EXPECT_NE(std::string(e.what()).find(input.string()), std::string::npos)
                    << e.what();
            }
        }
    }
    EXPECT_EQ(Entries(out), (std::vector<std::string>{"database.lldb", "loops.csv", "run.json"}));
    EXPECT_NO_THROW(RunFolder(dir / "other", {"", {out / "loops.csv"}, false}));
}

// A file in a lidarloop folder that no run.json lists is the user's: a run that would replace
// it fails, and the folder stays as it was.
TEST(RunFolder, AnUnlistedFileOfTheSameNameIsNotReplaced) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    WriteDetectResults(out);
    test::WriteFile(out / "report.md", "my notes");
    EXPECT_THROW(RunInFolder(out, {},
                             [](const fs::path& staging) {
                                 test::WriteFile(staging / "loops.csv", "second");
                                 test::WriteFile(staging / "report.md", "generated");
                                 return 0;
                             }),
                 io::WriteError);
    EXPECT_EQ(test::ReadFile(out / "report.md"), "my notes");
    EXPECT_EQ(test::ReadFile(out / "loops.csv"), "first");
    EXPECT_EQ(Manifest(out)["status"], "complete");
    RunInFolder(out, {"", {}, /*overwrite=*/true}, [](const fs::path& staging) {
        test::WriteFile(staging / "report.md", "generated");
        return 0;
    });
    EXPECT_EQ(test::ReadFile(out / "report.md"), "generated");
    EXPECT_EQ(Entries(out), (std::vector<std::string>{"report.md", "run.json"}));
}

// A sequence is input to other runs: only --overwrite replaces it, by a sequence or results.
TEST(RunFolder, ASequenceIsReplacedOnlyWhenToldTo) {
    test::TempDir dir;
    const fs::path sequence = dir / "sequence";
    const RunInfo dataset_run{"lidarloop simulate", {}, false, io::RunKind::kDataset};
    RunInFolder(sequence, dataset_run, [](const fs::path& staging) {
        test::WriteFile(staging / "poses.txt", "1");
        return 0;
    });
    EXPECT_EQ(Manifest(sequence)["kind"], "dataset");
    EXPECT_THROW(RunFolder(sequence, dataset_run), io::WriteError);
    EXPECT_THROW(RunFolder(sequence, {"lidarloop detect", {}, false}), io::WriteError);
    EXPECT_EQ(test::ReadFile(sequence / "poses.txt"), "1");
    RunInfo replace = dataset_run;
    replace.overwrite = true;
    RunInFolder(sequence, replace, [](const fs::path& staging) {
        test::WriteFile(staging / "poses.txt", "2");
        return 0;
    });
    EXPECT_EQ(test::ReadFile(sequence / "poses.txt"), "2");
    // Results into a results folder need no flag.
    WriteDetectResults(dir / "results");
    EXPECT_NO_THROW(WriteDetectResults(dir / "results"));
}

RunInfo CommandRun(const std::string& command, bool overwrite = false) {
    RunInfo info;
    info.command_line = "lidarloop " + command;
    info.overwrite = overwrite;
    info.command = command;
    return info;
}

// `evaluate --out X` after `detect --out X` would remove the map detect built: another command's
// results are replaced only with --overwrite; the same command's, as ever, without it.
TEST(RunFolder, AnotherCommandsResultsAreReplacedOnlyWhenToldTo) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    const auto write = [&](const RunInfo& info, const std::string& text) {
        RunInFolder(out, info, [&](const fs::path& staging) {
            test::WriteFile(staging / (info.command + ".txt"), text);
            return 0;
        });
    };
    write(CommandRun("detect"), "first");
    EXPECT_EQ(Manifest(out)["command"], "detect");
    try {
        write(CommandRun("evaluate"), "second");
        ADD_FAILURE() << "evaluate replaced detect's results";
    } catch (const io::WriteError& e) {
        EXPECT_NE(std::string(e.what()).find("holds the results of `lidarloop detect`"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_EQ(test::ReadFile(out / "detect.txt"), "first");
    EXPECT_NO_THROW(write(CommandRun("detect"), "again"));
    EXPECT_EQ(test::ReadFile(out / "detect.txt"), "again");
    EXPECT_NO_THROW(write(CommandRun("evaluate", /*overwrite=*/true), "replaced"));
    EXPECT_EQ(Entries(out), (std::vector<std::string>{"evaluate.txt", "run.json"}));
    // A run.json from before the command was recorded names none: any results command follows.
    nlohmann::json legacy = Manifest(out);
    legacy.erase("command");
    test::WriteFile(out / "run.json", legacy.dump());
    EXPECT_NO_THROW(write(CommandRun("detect"), "after legacy"));
}

// A command that writes several folders (demo) checks them all before its work: CheckRunFolder
// refuses what a run would refuse and creates or changes nothing.
TEST(RunFolder, CheckRefusesWhatARunWouldAndChangesNothing) {
    test::TempDir dir;
    const fs::path fresh = dir / "new";
    EXPECT_NO_THROW(CheckRunFolder(fresh, CommandRun("detect")));
    EXPECT_FALSE(fs::exists(fresh));

    const fs::path users = dir / "users";
    fs::create_directories(users);
    test::WriteFile(users / "mine.txt", "mine");
    EXPECT_THROW(CheckRunFolder(users, CommandRun("detect")), io::WriteError);
    EXPECT_NO_THROW(CheckRunFolder(users, CommandRun("detect", /*overwrite=*/true)));
    EXPECT_THROW(CheckRunFolder(users / "mine.txt", CommandRun("detect", true)), io::WriteError);
    EXPECT_EQ(Entries(users), std::vector<std::string>{"mine.txt"});

    const fs::path results = dir / "results";
    RunInFolder(results, CommandRun("detect"), [](const fs::path& staging) {
        test::WriteFile(staging / "loops.csv", "loops");
        return 0;
    });
    EXPECT_NO_THROW(CheckRunFolder(results, CommandRun("detect")));
    EXPECT_THROW(CheckRunFolder(results, CommandRun("evaluate")), io::WriteError);

    RunInfo reading_users = CommandRun("detect");
    reading_users.inputs = {users};
    EXPECT_THROW(CheckRunFolder(users / "out", reading_users), io::WriteError);
    EXPECT_THROW(CheckRunFolder(dir.path(), reading_users), io::WriteError);
    EXPECT_EQ(Entries(users), std::vector<std::string>{"mine.txt"});
}

// --overwrite replaces files of the same names; a folder of the user's is replaced as a whole,
// so one that no run.json lists is refused even then (an empty one is no loss).
TEST(RunFolder, AnUnlistedFolderOfTheSameNameIsNeverReplaced) {
    test::TempDir dir;
    const fs::path out = dir / "mine";
    fs::create_directories(out / "velodyne");
    test::WriteFile(out / "velodyne" / "notes.txt", "mine");
    test::WriteFile(out / "poses.txt", "my poses");
    fs::create_directories(out / "detection");
    const auto run = [&] {
        RunInFolder(out, CommandRun("simulate", /*overwrite=*/true), [](const fs::path& staging) {
            fs::create_directories(staging / "velodyne");
            test::WriteFile(staging / "velodyne" / "000000.bin", "scan");
            fs::create_directories(staging / "detection");
            test::WriteFile(staging / "poses.txt", "simulated");
            return 0;
        });
    };
    EXPECT_THROW(run(), io::WriteError);
    EXPECT_EQ(test::ReadFile(out / "velodyne" / "notes.txt"), "mine");
    EXPECT_EQ(test::ReadFile(out / "poses.txt"), "my poses");
    // No failure record either: a run.json saying "failed" would make every reader refuse the
    // user's sequence as unfinished.
    EXPECT_FALSE(fs::exists(out / "run.json"));
    fs::remove(out / "velodyne" / "notes.txt");
    EXPECT_NO_THROW(run());
    EXPECT_EQ(test::ReadFile(out / "poses.txt"), "simulated");
}

// A failed run into a folder of the user's (--overwrite) keeps the user's own run.json.
TEST(RunFolder, AFailedRunKeepsTheUsersOwnRunJson) {
    test::TempDir dir;
    const fs::path out = dir / "mine";
    fs::create_directories(out);
    test::WriteFile(out / "run.json", R"({"my": "experiment"})");
    EXPECT_THROW(RunInFolder(out, CommandRun("detect", /*overwrite=*/true),
                             [](const fs::path&) -> int { throw io::WriteError("x", "failed"); }),
                 io::WriteError);
    EXPECT_EQ(test::ReadFile(out / "run.json"), R"({"my": "experiment"})");
    EXPECT_EQ(Entries(out), std::vector<std::string>{"run.json"});
}

// A run.json whose fields have the wrong types is no record, not a crash.
TEST(RunFolder, ARunJsonOfWrongTypesIsNoRecord) {
    test::TempDir dir;
    test::WriteFile(dir / "run.json",
                    R"({"tool": "lidarloop", "status": 5, "kind": [], "command": 1})");
    const auto record = io::ReadRunRecord(dir.path());
    ASSERT_TRUE(record.has_value());
    EXPECT_EQ(record->status, "");
    EXPECT_EQ(record->command, "");
    EXPECT_EQ(record->kind, io::RunKind::kResults);
}

// What a killed run leaves is removed; what a running one uses is not.
TEST(RunFolder, LeftoversOfKilledRunsAreRemoved) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    WriteDetectResults(out);
    const fs::path dead = out / ".lidarloop-staging-2147483000-0";  // no such process
    const fs::path dead_aside = out / ".lidarloop-earlier-2147483000-0";
    const fs::path live = out / (".lidarloop-staging-" + std::to_string(::getppid()) + "-0");
    for (const fs::path& folder : {dead, dead_aside, live}) fs::create_directories(folder / "x");
    WriteDetectResults(out);
    EXPECT_FALSE(fs::exists(dead));
    EXPECT_FALSE(fs::exists(dead_aside));
    EXPECT_TRUE(fs::exists(live));
}

// A run killed in the middle of its swap (SIGKILL, a power cut) left the only copy of the earlier
// results in its earlier-files folder: the next run into the folder puts them back, and removes
// what the killed run had moved in, even when that next run is then refused.
TEST(RunFolder, AKilledSwapIsUndoneByTheNextRun) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    WriteDetectResults(out);  // loops.csv "first", database.lldb "map"
    const std::string record = test::ReadFile(out / "run.json");
    const fs::path aside = out / ".lidarloop-earlier-2147483000-0";  // no such process
    // Killed while moving in: both earlier files aside, one new file in.
    fs::create_directories(aside);
    fs::rename(out / "loops.csv", aside / "loops.csv");
    fs::rename(out / "database.lldb", aside / "database.lldb");
    test::WriteFile(aside / ".lidarloop-incoming", "loops.csv\nnew.txt\n");
    test::WriteFile(out / "loops.csv", "second");
    test::WriteFile(out / "new.txt", "new");
    RunInfo simulate;  // refused: a sequence over results
    simulate.kind = io::RunKind::kDataset;
    EXPECT_THROW(RunFolder(out, simulate), io::WriteError);
    EXPECT_EQ(test::ReadFile(out / "loops.csv"), "first");
    EXPECT_EQ(test::ReadFile(out / "database.lldb"), "map");
    EXPECT_EQ(test::ReadFile(out / "run.json"), record);
    EXPECT_EQ(Entries(out), (std::vector<std::string>{"database.lldb", "loops.csv", "run.json"}));
    // Killed while moving aside: nothing moved in yet, no list of incoming names.
    fs::create_directories(aside);
    fs::rename(out / "loops.csv", aside / "loops.csv");
    EXPECT_THROW(RunFolder(out, simulate), io::WriteError);
    EXPECT_EQ(test::ReadFile(out / "loops.csv"), "first");
    EXPECT_EQ(Entries(out), (std::vector<std::string>{"database.lldb", "loops.csv", "run.json"}));
}

// Killed after its run.json was written, a run had completed: what it moved aside is only what
// it replaced, and is removed, not put back.
TEST(RunFolder, AKilledCompletedSwapIsNotUndone) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    WriteDetectResults(out);
    RunInFolder(out, {}, [](const fs::path& staging) {
        test::WriteFile(staging / "loops.csv", "second");
        return 0;
    });
    const std::string aside_name = Manifest(out)["earlier_folder"].get<std::string>();
    ASSERT_EQ(aside_name.rfind(".lidarloop-earlier-" + std::to_string(::getpid()), 0), 0u);
    // The same state as if killed before removing it, under a dead process's name.
    const fs::path aside = out / ".lidarloop-earlier-2147483000-0";
    nlohmann::json manifest = Manifest(out);
    manifest["earlier_folder"] = aside.filename().string();
    test::WriteFile(out / "run.json", manifest.dump(2));
    fs::create_directories(aside);
    test::WriteFile(aside / "loops.csv", "first");
    test::WriteFile(aside / ".lidarloop-incoming", "loops.csv\n");
    RunFolder next(out, {});
    EXPECT_FALSE(fs::exists(aside));
    EXPECT_EQ(test::ReadFile(out / "loops.csv"), "second");
}

// Issue 25 (5): bench --json must not replace the ground truth or a scan of the dataset.
TEST(WriteOutputJson, ReplacesOnlyWhatLidarloopWroteAndNothingInsideAnInput) {
    test::TempDir dir;
    const fs::path dataset = dir / "sequence";
    fs::create_directories(dataset);
    test::WriteFile(dataset / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0");
    for (const fs::path& file : {dataset / "poses.txt", dataset / "velodyne" / "zz.bin", dataset}) {
        EXPECT_THROW(WriteOutputJson(file, {{"a", 1}}, {dataset}, /*overwrite=*/true),
                     io::WriteError)
            << file;
    }
    EXPECT_EQ(test::ReadFile(dataset / "poses.txt"), "1 0 0 0 0 1 0 0 0 0 1 0");
    EXPECT_FALSE(fs::exists(dataset / "velodyne"));

    const fs::path figures = dir / "bench.json";
    WriteOutputJson(figures, {{"a", 1}}, {dataset}, false);
    WriteOutputJson(figures, {{"a", 2}}, {dataset}, false);  // its own: replaced
    EXPECT_EQ(nlohmann::json::parse(test::ReadFile(figures))["a"], 2);
    EXPECT_EQ(nlohmann::json::parse(test::ReadFile(figures))["tool"], "lidarloop");

    const fs::path notes = dir / "notes.json";
    test::WriteFile(notes, R"({"mine": true})");
    EXPECT_THROW(WriteOutputJson(notes, {{"a", 1}}, {}, false), io::WriteError);
    EXPECT_EQ(test::ReadFile(notes), R"({"mine": true})");
    WriteOutputJson(notes, {{"a", 1}}, {}, /*overwrite=*/true);
    EXPECT_EQ(nlohmann::json::parse(test::ReadFile(notes))["a"], 1);
}

// A file of a run folder belongs to that run: bench --json over its run.json (or map --out over
// an optimise folder's map) would leave the folder describing results it no longer holds.
TEST(WriteOutputJson, AFileOfARunFolderIsReplacedOnlyWhenToldTo) {
    test::TempDir dir;
    const fs::path out = dir / "results";
    RunInFolder(out, CommandRun("detect"), [](const fs::path& staging) {
        test::WriteFile(staging / "figures.json", R"({"tool": "lidarloop"})");
        return 0;
    });
    const std::string record = test::ReadFile(out / "run.json");
    for (const fs::path& file : {out / "run.json", out / "figures.json"}) {
        EXPECT_THROW(WriteOutputJson(file, {{"a", 1}}, {}, false), io::WriteError) << file;
    }
    EXPECT_EQ(test::ReadFile(out / "run.json"), record);
    EXPECT_EQ(test::ReadFile(out / "figures.json"), R"({"tool": "lidarloop"})");
    WriteOutputJson(out / "bench.json", {{"a", 1}}, {}, false);  // not the run's: a new file
    WriteOutputJson(out / "bench.json", {{"a", 2}}, {}, false);  // and its own to replace
    WriteOutputJson(out / "figures.json", {{"a", 1}}, {}, /*overwrite=*/true);
    EXPECT_EQ(nlohmann::json::parse(test::ReadFile(out / "figures.json"))["a"], 1);
    EXPECT_THROW(WriteOutputJson("", {{"a", 1}}, {}, true), io::WriteError);
}

// bench checks its --json file before measuring: a folder it cannot write into is an error then.
TEST(WriteOutputJson, AReadOnlyFolderIsRefusedBeforeTheRun) {
    if (::geteuid() == 0) GTEST_SKIP() << "root may write into a read-only folder";
    test::TempDir dir;
    const fs::path folder = dir / "read_only";
    fs::create_directories(folder);
    fs::permissions(folder, fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_THROW(CheckOutputFile(folder / "bench.json", {}, false), io::WriteError);
    fs::permissions(folder, fs::perms::owner_all);
    EXPECT_NO_THROW(CheckOutputFile(folder / "bench.json", {}, false));
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

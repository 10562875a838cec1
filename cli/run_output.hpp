#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "lidarloop/app/run_folder.hpp"

namespace lidarloop::cli {

/// Called first in main, before any other thread exists: SIGINT and SIGTERM are blocked in
/// every thread and handled by a watcher thread, which abandons the results folder of the
/// running command (app::AbandonActiveRun) as interrupted, says so on stderr and exits with
/// 128 + the signal.
void InstallInterruptHandler(int argc, char** argv);

/// True once SIGINT or SIGTERM has arrived. The watcher then removes the running folder's
/// staging files, so the command may fail on them (a file it cannot open): that error and its
/// exit code are the interrupt's, not the command's, and main leaves the exit to the watcher.
bool InterruptReceived();

/// Waits for the watcher to end the process (128 + the signal); call only after
/// InterruptReceived() is true.
[[noreturn]] void AwaitInterruptExit();

/// The command line as typed (arguments joined by spaces), for run.json.
const std::string& CommandLine();
/// The command's name (detect, evaluate, ...), for run.json.
const std::string& CommandName();

/// The RunInfo of this command line.
inline app::RunInfo CommandRun(std::vector<std::filesystem::path> inputs, bool overwrite) {
    return app::CommandRunInfo(CommandName(), CommandLine(), std::move(inputs), overwrite);
}

/// app::RunInFolder for a command: `inputs` are the files and folders it reads, which `out` may
/// neither lie inside nor hold; `overwrite` allows a non-empty folder of other files.
template <typename Run>
auto RunInFolder(const std::filesystem::path& out, std::vector<std::filesystem::path> inputs,
                 bool overwrite, Run&& run) {
    return app::RunInFolder(out, CommandRun(std::move(inputs), overwrite), std::forward<Run>(run));
}

}  // namespace lidarloop::cli

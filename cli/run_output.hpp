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

/// The command line as typed (arguments joined by spaces), for run.json.
const std::string& CommandLine();

/// app::RunInFolder for a command: `inputs` are the files and folders it reads, which `out` may
/// neither lie inside nor hold; `overwrite` allows a non-empty folder of other files.
template <typename Run>
auto RunInFolder(const std::filesystem::path& out, std::vector<std::filesystem::path> inputs,
                 bool overwrite, Run&& run) {
    return app::RunInFolder(out, {CommandLine(), std::move(inputs), overwrite},
                            std::forward<Run>(run));
}

}  // namespace lidarloop::cli

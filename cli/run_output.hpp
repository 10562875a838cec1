#pragma once

#include <exception>
#include <filesystem>
#include <string>

#include "lidarloop/app/run_folder.hpp"

namespace lidarloop::cli {

/// Called first in main, before any other thread exists: SIGINT and SIGTERM are blocked in
/// every thread and handled by a watcher thread, which abandons the results folder of the
/// running command (InterruptScope) as interrupted, says so on stderr and exits with
/// 128 + the signal.
void InstallInterruptHandler(int argc, char** argv);

/// The command line as typed (arguments joined by spaces), for run.json.
const std::string& CommandLine();

/// While alive, an interrupt abandons `folder` (app::RunStatus::kInterrupted).
class InterruptScope {
public:
    explicit InterruptScope(app::RunFolder& folder);
    ~InterruptScope();
    InterruptScope(const InterruptScope&) = delete;
    InterruptScope& operator=(const InterruptScope&) = delete;
};

/// Runs `run(staging)` for a results folder `out` (app::RunFolder: `dataset` is the folder read,
/// which `out` must lie outside; `overwrite` allows a non-empty folder of other files), then
/// moves its files into place and writes run.json; on an error or an interrupt only run.json is
/// left, saying so. Returns what `run` returns.
template <typename Run>
auto RunInFolder(const std::filesystem::path& out, const std::filesystem::path& dataset,
                 bool overwrite, Run&& run) {
    app::RunFolder folder(out, {CommandLine(), dataset, overwrite});
    InterruptScope interruptible(folder);
    try {
        auto result = run(folder.staging());
        folder.Complete();
        return result;
    } catch (const std::exception& e) {
        folder.Abandon(app::RunStatus::kFailed, e.what());
        throw;
    }
}

}  // namespace lidarloop::cli

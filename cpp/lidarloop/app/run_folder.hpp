#pragma once

#include <filesystem>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace lidarloop::app {

/// How a run ended, as its run.json says.
enum class RunStatus { kComplete, kFailed, kInterrupted };

/// "complete", "failed", "interrupted".
std::string ToString(RunStatus status);

/// What a RunFolder checks and records besides its files.
struct RunInfo {
    std::string command_line;       ///< the command as typed, for run.json
    std::filesystem::path dataset;  ///< the folder the run reads (empty: none)
    /// Write into a non-empty folder that holds no lidarloop run.json (its other files stay).
    bool overwrite = false;
};

/// A results folder that never lies (what `detect` and `evaluate` write into):
/// - the run writes into staging(), a hidden folder inside it, and Complete() moves every file
///   into place by renaming (a file is whole or absent, never half-written), then writes
///   run.json last: version, command line, status, start and end time (UTC), the files;
/// - a run that fails or is interrupted leaves none of its files, only a run.json saying so;
/// - the files of the run before, which its run.json lists, are removed first, so none
///   survives into this run's results;
/// - a folder inside the dataset (whose files would be read as scans), and a non-empty folder
///   without a lidarloop run.json unless RunInfo::overwrite, are refused.
/// Complete and Abandon are thread-safe with each other (Abandon may come from a signal
/// watcher thread); the first of them decides.
class RunFolder {
public:
    /// Checks and prepares `folder` (created with its parents). Throws io::WriteError naming
    /// the folder when it is refused or cannot be written.
    RunFolder(std::filesystem::path folder, RunInfo info);
    /// Abandons the run as failed unless it was completed or abandoned.
    ~RunFolder();
    RunFolder(const RunFolder&) = delete;
    RunFolder& operator=(const RunFolder&) = delete;

    const std::filesystem::path& folder() const { return folder_; }
    /// Where the run writes its files.
    const std::filesystem::path& staging() const { return staging_; }

    /// Moves the files of staging() into folder() and writes run.json (status complete).
    /// Returns the files' names, sorted. Throws io::WriteError (then run.json says failed).
    std::vector<std::string> Complete();
    /// Removes staging() and writes run.json with `status` and `message`; never throws.
    void Abandon(RunStatus status, const std::string& message) noexcept;

private:
    void WriteManifest(RunStatus status, const std::vector<std::string>& files,
                       const std::string& message) const;

    std::filesystem::path folder_;
    std::filesystem::path staging_;
    RunInfo info_;
    std::string started_;
    std::mutex mutex_;
    bool finished_ = false;
};

/// While alive, `folder` is the process's running results folder, which AbandonActiveRun
/// abandons (one at a time: a second ActiveRun replaces the first until it ends).
class ActiveRun {
public:
    explicit ActiveRun(RunFolder& folder);
    ~ActiveRun();
    ActiveRun(const ActiveRun&) = delete;
    ActiveRun& operator=(const ActiveRun&) = delete;

private:
    RunFolder* previous_;
};

/// Abandons the running results folder (see ActiveRun) with `status` and `message`, for a signal
/// watcher thread about to end the process. Returns that folder, or an empty path when no run
/// writes one. Thread-safe; never throws.
std::filesystem::path AbandonActiveRun(RunStatus status, const std::string& message) noexcept;

/// Runs `run(staging)` for the results folder `out` with RunFolder's guarantees: when `run`
/// returns, its files move into place and run.json says complete; when it throws, only a
/// run.json saying failed is left and the error propagates; meanwhile AbandonActiveRun can stop
/// it as interrupted. What library callers, the CLI and Python use to write a results folder.
/// Returns what `run` returns.
template <typename Run>
auto RunInFolder(const std::filesystem::path& out, RunInfo info, Run&& run) {
    RunFolder folder(out, std::move(info));
    const ActiveRun active(folder);
    try {
        auto result = std::forward<Run>(run)(folder.staging());
        folder.Complete();
        return result;
    } catch (const std::exception& e) {
        folder.Abandon(RunStatus::kFailed, e.what());
        throw;
    }
}

}  // namespace lidarloop::app

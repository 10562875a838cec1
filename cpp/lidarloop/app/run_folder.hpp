#pragma once

#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarloop/io/run_record.hpp"

namespace lidarloop::app {

/// How a run ended, as its run.json says.
enum class RunStatus { kComplete, kFailed, kInterrupted };

/// "complete", "failed", "interrupted".
std::string ToString(RunStatus status);

/// What a RunFolder checks and records besides its files.
struct RunInfo {
    std::string command_line;  ///< the command as typed, for run.json
    /// Every file and folder the run reads (dataset, poses, map, loops, odometry); the results
    /// folder may neither lie inside one nor hold one. Empty paths are ignored.
    std::vector<std::filesystem::path> inputs;
    /// Write into a non-empty folder that holds no lidarloop run.json, or one of the other kind,
    /// replacing the files of the same names (its other files stay).
    bool overwrite = false;
    io::RunKind kind = io::RunKind::kResults;  ///< what run.json says the folder holds
    /// The command's name (detect, evaluate, ...), for run.json: the results of another command
    /// are replaced only with `overwrite`. Empty: any (runs written before it was recorded).
    std::string command = {};
};

/// The RunInfo of command `command` (detect, evaluate, ...) writing results, typed as
/// `command_line`: what the CLI and the Python package both record.
RunInfo CommandRunInfo(std::string command, std::string command_line,
                       std::vector<std::filesystem::path> inputs, bool overwrite);

/// The results-folder rule of every command that writes (docs/cli.md, "Results folders"):
/// - a folder inside an input, or holding an input, is refused before anything is written;
/// - a non-empty folder without a lidarloop run.json, or with one of the other kind (results
///   against a simulated dataset) or of another command (evaluate into detect's results), is
///   refused unless RunInfo::overwrite;
/// - the run writes into staging(), a hidden folder inside it; Complete() moves the earlier
///   run's files aside, renames the new ones into place (a file is whole or absent, never
///   half-written), writes run.json last (version, command line, kind, status, start and end
///   time in UTC, the files) and only then deletes the earlier files;
/// - a run that fails or is interrupted leaves the earlier run's files and run.json as they
///   were; in a folder without an earlier run it leaves only a run.json saying how it ended;
/// - a file of the folder that no run.json lists is never replaced unless RunInfo::overwrite, and
///   a non-empty subfolder that none lists never (it is replaced as a whole: the user's files).
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
    /// Removes staging(); writes run.json with `status` and `message` unless the folder holds
    /// an earlier run's results, which stay as they were. Never throws.
    void Abandon(RunStatus status, const std::string& message) noexcept;

private:
    void SwapIn(const std::vector<std::string>& staged);
    void WriteManifest(RunStatus status, const std::vector<std::string>& files,
                       const std::string& message, const std::string& earlier_folder = "") const;
    void RecordFailure(RunStatus status, const std::string& message) noexcept;

    std::filesystem::path folder_;
    std::filesystem::path staging_;
    RunInfo info_;
    std::string started_;
    std::mutex mutex_;
    bool finished_ = false;
};

/// RunFolder's refusals of `folder` for a run with `info`, without creating or changing
/// anything: for a command that writes several folders (demo), so that a later folder is refused
/// before the work for the earlier ones. A folder that does not exist yet passes. Throws
/// io::WriteError naming the folder, as RunFolder would.
void CheckRunFolder(const std::filesystem::path& folder, const RunInfo& info);

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

/// Writes `text` to `file` beside it first and then renames it, so that `file` is whole or
/// absent. Throws io::WriteError.
void WriteFileAtomically(const std::filesystem::path& file, const std::string& text);
/// The same for any writer: `write(temporary)` writes a file beside `file` (removed when `write`
/// throws), which then replaces `file`.
void WriteFileAtomically(const std::filesystem::path& file,
                         const std::function<void(const std::filesystem::path& temporary)>& write);

/// The results-folder rule for one output file: throws io::WriteError when `file` is or lies
/// inside one of `inputs`, is a folder, or exists and is not a JSON or PLY file that lidarloop
/// wrote (unless `overwrite`).
void CheckOutputFile(const std::filesystem::path& file,
                     const std::vector<std::filesystem::path>& inputs, bool overwrite);

/// Writes `json` with "tool": "lidarloop" to `file` (bench --json) after CheckOutputFile,
/// atomically. Throws io::WriteError.
void WriteOutputJson(const std::filesystem::path& file, nlohmann::json json,
                     const std::vector<std::filesystem::path>& inputs, bool overwrite);

/// Runs `run(staging)` for the results folder `out` with RunFolder's guarantees: when `run`
/// returns, its files replace the earlier run's and run.json says complete; when it throws, the
/// folder is left as it was (or with a run.json saying failed) and the error propagates; meanwhile
/// AbandonActiveRun can stop it as interrupted. What library callers, the CLI and Python use to
/// write a results folder. Returns what `run` returns.
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

#include "lidarloop/app/run_folder.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>

#include "lidarloop/io/map_files.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::app {
namespace fs = std::filesystem;
namespace {

constexpr char kStagingPrefix[] = ".lidarloop-staging-";
constexpr char kEarlierPrefix[] = ".lidarloop-earlier-";
// In an earlier-files folder: the names a run moves in, written once the earlier files are aside.
constexpr char kIncomingName[] = ".lidarloop-incoming";
// The run.json key naming the earlier-files folder of the run that wrote it.
constexpr char kEarlierFolderKey[] = "earlier_folder";

std::string UtcNow() {
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char text[32];
    std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
    return text;
}

// True when `inner` is `outer` or lies below it, after resolving links and "..".
bool IsInside(const fs::path& inner, const fs::path& outer) {
    std::error_code ec;
    const fs::path a = fs::weakly_canonical(inner, ec);
    const fs::path b = fs::weakly_canonical(outer, ec);
    if (ec || b.empty()) return false;
    const auto [end_b, end_a] = std::mismatch(b.begin(), b.end(), a.begin(), a.end());
    return end_b == b.end() || (std::next(end_b) == b.end() && end_b->empty());
}

// An output inside an input would be read as input (scans) or replace it; an input inside the
// output would be replaced by the results. Both are refused before anything is written.
void RefuseInputOverlap(const fs::path& output, const std::vector<fs::path>& inputs) {
    for (const fs::path& input : inputs) {
        if (input.empty()) continue;
        std::error_code ec;
        if (fs::equivalent(output, input, ec)) {
            throw io::WriteError(output, "is an input of this run; write the results elsewhere");
        }
        if (IsInside(output, input)) {
            throw io::WriteError(output, "lies inside the input " + input.string() +
                                             ", which the results would mix with or replace; "
                                             "write the results elsewhere");
        }
        if (IsInside(input, output)) {
            throw io::WriteError(output, "holds the input " + input.string() +
                                             ", which the results would replace; write the "
                                             "results elsewhere");
        }
    }
}

// A hidden folder of a run in progress or of one that was killed: ".lidarloop-staging-PID-N".
bool IsWorkFolder(const fs::path& entry) {
    const std::string name = entry.filename().string();
    return name.rfind(kStagingPrefix, 0) == 0 || name.rfind(kEarlierPrefix, 0) == 0;
}

// A killed process leaves its work folders; a live one (another run into the same folder) is
// still using them.
bool BelongsToLiveProcess(const fs::path& entry) {
    const std::string name = entry.filename().string();
    const std::size_t prefix = name.rfind(kStagingPrefix, 0) == 0 ? sizeof(kStagingPrefix) - 1
                                                                  : sizeof(kEarlierPrefix) - 1;
    long pid = 0;
    try {
        pid = std::stol(name.substr(prefix));
    } catch (const std::exception&) {
        return false;
    }
    return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
}

std::vector<std::string> ListNames(const fs::path& folder) {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec))
        names.push_back(entry.path().filename().string());
    if (ec) throw io::WriteError(folder, "cannot list (" + ec.message() + ")");
    std::sort(names.begin(), names.end());
    return names;
}

// Whether the folder's run.json was written by the run that moved the earlier files into
// `aside`: then that run completed, and `aside` holds only what it replaced.
bool RunJsonNames(const fs::path& folder, const fs::path& aside) {
    std::ifstream in(folder / io::kRunRecordName);
    const nlohmann::json json = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (!json.is_object()) return false;
    const auto named = json.find(kEarlierFolderKey);
    return named != json.end() && named->is_string() &&
           named->get<std::string>() == aside.filename().string();
}

// A run killed after moving the earlier files aside and before writing its run.json leaves the
// only copy of the earlier results in `aside`: they go back, and the files it had moved in go
// (each name it moved in either replaced an earlier file, now in `aside`, or was new).
void RestoreUnlessCompleted(const fs::path& folder, const fs::path& aside) {
    if (RunJsonNames(folder, aside)) return;
    std::error_code ec;
    std::ifstream incoming(aside / kIncomingName);
    for (std::string name; std::getline(incoming, name);) {
        if (!name.empty() && !fs::exists(aside / name, ec)) fs::remove_all(folder / name, ec);
    }
    for (const std::string& name : ListNames(aside)) {
        if (name == kIncomingName) continue;
        fs::remove_all(folder / name, ec);
        fs::rename(aside / name, folder / name, ec);
        if (ec) throw io::WriteError(aside / name, "cannot move back (" + ec.message() + ")");
    }
}

// Removes what killed runs left: their staging folders (half-written results), and folders of
// earlier files they had moved aside, put back first unless the run had completed.
void RemoveLeftovers(const fs::path& folder) {
    std::error_code ec;
    for (const std::string& name : ListNames(folder)) {
        const fs::path entry = folder / name;
        if (!IsWorkFolder(entry) || BelongsToLiveProcess(entry)) continue;
        if (name.rfind(kEarlierPrefix, 0) == 0) RestoreUnlessCompleted(folder, entry);
        fs::remove_all(entry, ec);
    }
}

bool HoldsOnlyLeftovers(const fs::path& folder) {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
        if (!IsWorkFolder(entry.path())) return false;
    }
    return true;
}

// What may be replaced without being told to overwrite: nothing in a new or empty folder, the
// files of an earlier run of results. A dataset is input to other runs: replacing it would
// leave their results describing scans that no longer exist.
void RefuseForeignFolder(const fs::path& folder, const std::optional<io::RunRecord>& earlier,
                         const RunInfo& info) {
    if (info.overwrite) return;
    const bool holds_files = earlier && !earlier->files.empty();
    if (holds_files && (earlier->kind != info.kind || earlier->kind == io::RunKind::kDataset)) {
        throw io::WriteError(
            folder,
            "holds a lidarloop " + io::ToString(earlier->kind) +
                (earlier->kind == io::RunKind::kDataset ? " (a sequence of scans)" : " folder") +
                "; choose another folder, or give --overwrite to "
                "replace it");
    }
    if (holds_files && !earlier->command.empty() && !info.command.empty() &&
        earlier->command != info.command) {
        throw io::WriteError(folder, "holds the results of `lidarloop " + earlier->command +
                                         "`; choose another folder, or give --overwrite to "
                                         "replace them");
    }
    if (!earlier && !HoldsOnlyLeftovers(folder)) {
        throw io::WriteError(folder,
                             "is not empty and holds no lidarloop run.json; choose an empty or new "
                             "folder, or give --overwrite to write into it anyway");
    }
}

std::string UniqueSuffix() {
    static std::atomic<unsigned> count{0};
    return std::to_string(::getpid()) + "-" + std::to_string(count++);
}

bool Contains(const std::vector<std::string>& names, const std::string& name) {
    return std::find(names.begin(), names.end(), name) != names.end();
}

void Rename(const fs::path& from, const fs::path& to) {
    std::error_code ec;
    fs::rename(from, to, ec);
    if (ec) throw io::WriteError(to, "cannot move into place (" + ec.message() + ")");
}

// The proof that replacing `file` loses nothing of the user's: lidarloop wrote it.
bool IsLidarloopJson(const fs::path& file) {
    std::ifstream in(file);
    const nlohmann::json json = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    return json.is_object() && json.value("tool", "") == "lidarloop";
}

// A file of a lidarloop run folder (one its run.json lists, or run.json itself) is part of that
// run's record: replaced alone, the folder would describe results it no longer holds.
void RefuseRunFolderFile(const fs::path& file) {
    const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
    const std::optional<io::RunRecord> record = io::ReadRunRecord(folder);
    const std::string name = file.filename().string();
    if (!record || (name != io::kRunRecordName && !Contains(record->files, name))) return;
    const std::string owner = record->command.empty()
                                  ? "a lidarloop " + io::ToString(record->kind)
                                  : "the results of `lidarloop " + record->command + "`";
    throw io::WriteError(file, "belongs to " + owner + " in " + folder.string() +
                                   "; choose another file, or give --overwrite to replace it");
}

std::mutex active_mutex;
RunFolder* active_folder = nullptr;  // guarded by active_mutex

// The moves of Complete(), undone in reverse when one fails: the earlier files go aside, the
// staged ones into place.
class FolderSwap {
public:
    FolderSwap(fs::path folder, fs::path staging, fs::path aside)
        : folder_(std::move(folder)), staging_(std::move(staging)), aside_(std::move(aside)) {}

    void MoveAside(const std::vector<std::string>& names) {
        std::error_code ec;
        fs::create_directory(aside_, ec);
        if (ec) throw io::WriteError(aside_, "cannot create (" + ec.message() + ")");
        for (const std::string& name : names) {
            Rename(folder_ / name, aside_ / name);
            aside_names_.push_back(name);
        }
    }

    // The names go into `aside` first: a run killed from here on is undone by the next run into
    // the folder (RestoreUnlessCompleted).
    void MoveIn(const std::vector<std::string>& names) {
        std::ofstream incoming(aside_ / kIncomingName);
        for (const std::string& name : names) incoming << name << '\n';
        incoming.close();
        if (!incoming) throw io::WriteError(aside_ / kIncomingName, "writing failed");
        for (const std::string& name : names) {
            Rename(staging_ / name, folder_ / name);
            in_names_.push_back(name);
        }
    }

    void Undo() noexcept {
        std::error_code ec;
        for (const std::string& name : in_names_) fs::remove_all(folder_ / name, ec);
        for (const std::string& name : aside_names_) fs::rename(aside_ / name, folder_ / name, ec);
        Finish();
    }

    void Finish() noexcept {
        std::error_code ec;
        fs::remove_all(aside_, ec);
        fs::remove_all(staging_, ec);
    }

private:
    fs::path folder_;
    fs::path staging_;
    fs::path aside_;
    std::vector<std::string> aside_names_;
    std::vector<std::string> in_names_;
};

// The files in `folder` that the new run replaces: those of the same names, and every file the
// earlier run listed (none of them may survive into this run's results). A file no run.json
// lists is replaced only when told to overwrite.
std::vector<std::string> FilesToReplace(const fs::path& folder,
                                        const std::vector<std::string>& staged, bool overwrite) {
    const std::optional<io::RunRecord> earlier = io::ReadRunRecord(folder);
    const std::vector<std::string> listed = earlier ? earlier->files : std::vector<std::string>();
    std::vector<std::string> replaced;
    std::error_code ec;
    for (const std::string& name : staged) {
        if (!fs::exists(folder / name, ec)) continue;
        const bool unlisted = !Contains(listed, name);
        if (unlisted && !overwrite) {
            throw io::WriteError(folder / name,
                                 "exists, and no lidarloop run.json lists it; move it away, or "
                                 "give --overwrite to replace it");
        }
        // A folder is replaced as a whole: --overwrite names files, not folders of the user's.
        if (unlisted && fs::is_directory(folder / name, ec) && !fs::is_empty(folder / name, ec)) {
            throw io::WriteError(folder / name,
                                 "is a folder that no lidarloop run.json lists; it would be "
                                 "replaced as a whole: move it away, or choose another folder");
        }
        replaced.push_back(name);
    }
    for (const std::string& name : listed) {
        if (!Contains(staged, name) && fs::exists(folder / name, ec)) replaced.push_back(name);
    }
    return replaced;
}

}  // namespace

std::string ToString(RunStatus status) {
    switch (status) {
        case RunStatus::kComplete:
            return "complete";
        case RunStatus::kFailed:
            return "failed";
        case RunStatus::kInterrupted:
            return "interrupted";
    }
    return "failed";
}

RunInfo CommandRunInfo(std::string command, std::string command_line, std::vector<fs::path> inputs,
                       bool overwrite) {
    RunInfo info;
    info.command_line = std::move(command_line);
    info.inputs = std::move(inputs);
    info.overwrite = overwrite;
    info.command = std::move(command);
    return info;
}

void CheckRunFolder(const fs::path& folder, const RunInfo& info) {
    RefuseInputOverlap(folder, info.inputs);
    std::error_code ec;
    if (!fs::exists(folder, ec)) return;
    if (!fs::is_directory(folder, ec)) throw io::WriteError(folder, "is not a folder");
    RefuseForeignFolder(folder, io::ReadRunRecord(folder), info);
}

RunFolder::RunFolder(fs::path folder, RunInfo info)
    : folder_(std::move(folder)), info_(std::move(info)), started_(UtcNow()) {
    RefuseInputOverlap(folder_, info_.inputs);
    std::error_code ec;
    fs::create_directories(folder_, ec);
    if (ec || !fs::is_directory(folder_)) {
        throw io::WriteError(folder_, "cannot create the output folder" +
                                          (ec ? " (" + ec.message() + ")" : std::string()));
    }
    RemoveLeftovers(folder_);
    RefuseForeignFolder(folder_, io::ReadRunRecord(folder_), info_);
    staging_ = folder_ / (kStagingPrefix + UniqueSuffix());
    fs::create_directory(staging_, ec);
    if (ec)
        throw io::WriteError(staging_, "cannot create the staging folder (" + ec.message() + ")");
}

RunFolder::~RunFolder() { Abandon(RunStatus::kFailed, "the run stopped with an error"); }

std::vector<std::string> RunFolder::Complete() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) throw io::WriteError(folder_, "the run was already abandoned");
    finished_ = true;
    const fs::path aside = folder_ / (kEarlierPrefix + UniqueSuffix());
    FolderSwap swap(folder_, staging_, aside);
    std::vector<std::string> files;
    try {
        files = ListNames(staging_);
        swap.MoveAside(FilesToReplace(folder_, files, info_.overwrite));
        swap.MoveIn(files);
        // run.json is renamed into place last: until then the earlier one describes the folder.
        // It names `aside`, which tells the next run that this swap completed.
        WriteManifest(RunStatus::kComplete, files, "", aside.filename().string());
    } catch (const io::WriteError& e) {
        swap.Undo();
        RecordFailure(RunStatus::kFailed, e.what());
        throw;
    }
    swap.Finish();
    return files;
}

void RunFolder::Abandon(RunStatus status, const std::string& message) noexcept {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    finished_ = true;
    std::error_code ec;
    fs::remove_all(staging_, ec);
    RecordFailure(status, message);
}

// An earlier run's results stay as they were, run.json included; only a folder without results
// gets a run.json that says how this run ended: one that lidarloop's failed runs alone wrote
// into, or one that is empty. A folder of the user's (--overwrite) keeps its own run.json, and a
// dataset without a run.json is not marked unfinished by a run that never wrote into it.
void RunFolder::RecordFailure(RunStatus status, const std::string& message) noexcept {
    try {
        const std::optional<io::RunRecord> earlier = io::ReadRunRecord(folder_);
        if (earlier && !earlier->files.empty()) return;
        if (!earlier && !HoldsOnlyLeftovers(folder_)) return;
        WriteManifest(status, {}, message);
    } catch (const std::exception&) {  // the first error is the one to report
    }
}

ActiveRun::ActiveRun(RunFolder& folder) {
    const std::lock_guard<std::mutex> lock(active_mutex);
    previous_ = active_folder;
    active_folder = &folder;
}

ActiveRun::~ActiveRun() {
    const std::lock_guard<std::mutex> lock(active_mutex);
    active_folder = previous_;
}

fs::path AbandonActiveRun(RunStatus status, const std::string& message) noexcept {
    const std::lock_guard<std::mutex> lock(active_mutex);
    if (active_folder == nullptr) return {};
    active_folder->Abandon(status, message);
    try {
        return active_folder->folder();
    } catch (const std::exception&) {  // out of memory: the folder is abandoned all the same
        return {};
    }
}

void RunFolder::WriteManifest(RunStatus status, const std::vector<std::string>& files,
                              const std::string& message, const std::string& earlier_folder) const {
    nlohmann::json json;
    json["tool"] = "lidarloop";
    json["version"] = LIDARLOOP_VERSION;
    json["command_line"] = info_.command_line;
    json["kind"] = io::ToString(info_.kind);
    if (!info_.command.empty()) json["command"] = info_.command;
    json["status"] = ToString(status);
    json["started"] = started_;
    json["ended"] = UtcNow();
    json["files"] = files;
    if (!message.empty()) json["message"] = message;
    if (!earlier_folder.empty()) json[kEarlierFolderKey] = earlier_folder;
    WriteFileAtomically(folder_ / io::kRunRecordName, json.dump(2) + "\n");
}

void WriteFileAtomically(const fs::path& file,
                         const std::function<void(const fs::path& temporary)>& write) {
    const fs::path temporary =
        file.parent_path() / ("." + file.filename().string() + ".tmp-" + UniqueSuffix());
    std::error_code ec;
    try {
        write(temporary);
    } catch (...) {
        fs::remove(temporary, ec);
        throw;
    }
    fs::rename(temporary, file, ec);
    if (ec) {
        fs::remove(temporary, ec);
        throw io::WriteError(file, "cannot move into place (" + ec.message() + ")");
    }
}

void WriteFileAtomically(const fs::path& file, const std::string& text) {
    WriteFileAtomically(file, [&](const fs::path& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        if (!out) {
            throw io::WriteError(
                file, "cannot create a file beside it (" + std::string(std::strerror(errno)) + ")");
        }
        out << text;
        out.close();
        if (!out) throw io::WriteError(file, "writing failed (disk full?)");
    });
}

void CheckOutputFile(const fs::path& file, const std::vector<fs::path>& inputs, bool overwrite) {
    if (file.empty()) throw io::WriteError(file, "is an empty file name");
    RefuseInputOverlap(file, inputs);
    std::error_code ec;
    if (fs::is_directory(file, ec)) throw io::WriteError(file, "is a folder, not a file");
    // Checked before the run, so that a folder that cannot take the file costs no measurement.
    const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
    if (fs::is_directory(folder, ec) && ::access(folder.c_str(), W_OK) != 0) {
        throw io::WriteError(file, "cannot be written: its folder is not writable (" +
                                       std::string(std::strerror(errno)) + ")");
    }
    if (!overwrite) RefuseRunFolderFile(file);
    if (fs::exists(file, ec) && !overwrite && !IsLidarloopJson(file) && !io::IsLidarloopPly(file)) {
        throw io::WriteError(file,
                             "exists and is not a JSON or PLY file that lidarloop wrote; choose "
                             "another file, or give --overwrite to replace it");
    }
}

void WriteOutputJson(const fs::path& file, nlohmann::json json, const std::vector<fs::path>& inputs,
                     bool overwrite) {
    CheckOutputFile(file, inputs, overwrite);
    json["tool"] = "lidarloop";
    WriteFileAtomically(file, json.dump(2) + "\n");
}

}  // namespace lidarloop::app

#include "lidarloop/app/run_folder.hpp"

#include <unistd.h>

#include <algorithm>
#include <ctime>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>

#include "lidarloop/io/read_error.hpp"

namespace lidarloop::app {
namespace fs = std::filesystem;
namespace {

constexpr char kManifest[] = "run.json";
constexpr char kStagingPrefix[] = ".lidarloop-staging-";

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

// A name run.json may list: a plain file name in the folder, nothing that leads elsewhere.
bool IsPlainName(const std::string& name) {
    return !name.empty() && name != "." && name != ".." && fs::path(name).filename() == name;
}

// The files the earlier run's run.json lists; nullopt when there is no lidarloop run.json.
std::optional<std::vector<std::string>> PreviousRunFiles(const fs::path& folder) {
    std::ifstream in(folder / kManifest);
    if (!in) return std::nullopt;
    const nlohmann::json json = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (!json.is_object() || json.value("tool", "") != "lidarloop") return std::nullopt;
    std::vector<std::string> files;
    if (json.contains("files") && json["files"].is_array()) {
        for (const auto& file : json["files"]) {
            if (file.is_string() && IsPlainName(file.get<std::string>()))
                files.push_back(file.get<std::string>());
        }
    }
    return files;
}

std::mutex active_mutex;
RunFolder* active_folder = nullptr;  // guarded by active_mutex

bool IsStaging(const fs::path& entry) {
    return entry.filename().string().rfind(kStagingPrefix, 0) == 0;
}

// Removes what an earlier run left: the files and folders its run.json lists (optimise's
// detection/), run.json, and staging folders of runs that were killed. Refuses a non-empty folder
// of other files unless told to.
void ClearPreviousRun(const fs::path& folder, bool overwrite) {
    std::error_code ec;
    const auto previous = PreviousRunFiles(folder);
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
        if (IsStaging(entry.path())) fs::remove_all(entry.path(), ec);
    }
    if (previous) {
        for (const std::string& file : *previous) fs::remove_all(folder / file, ec);
        fs::remove(folder / kManifest, ec);
        return;
    }
    if (!overwrite && !fs::is_empty(folder, ec)) {
        throw io::WriteError(folder,
                             "is not empty and holds no lidarloop run.json; choose an empty or new "
                             "folder, or give --overwrite to write into it anyway");
    }
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

RunFolder::RunFolder(fs::path folder, RunInfo info)
    : folder_(std::move(folder)), info_(std::move(info)), started_(UtcNow()) {
    if (!info_.dataset.empty() && IsInside(folder_, info_.dataset)) {
        throw io::WriteError(folder_, "lies inside the dataset " + info_.dataset.string() +
                                          ", whose scans it would mix with; write the results "
                                          "elsewhere");
    }
    std::error_code ec;
    fs::create_directories(folder_, ec);
    if (ec || !fs::is_directory(folder_)) {
        throw io::WriteError(folder_, "cannot create the output folder" +
                                          (ec ? " (" + ec.message() + ")" : std::string()));
    }
    ClearPreviousRun(folder_, info_.overwrite);
    staging_ = folder_ / (kStagingPrefix + std::to_string(::getpid()));
    fs::create_directory(staging_, ec);
    if (ec)
        throw io::WriteError(staging_, "cannot create the staging folder (" + ec.message() + ")");
}

RunFolder::~RunFolder() { Abandon(RunStatus::kFailed, "the run stopped with an error"); }

std::vector<std::string> RunFolder::Complete() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) throw io::WriteError(folder_, "the run was already abandoned");
    std::vector<std::string> files;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(staging_, ec))
        files.push_back(entry.path().filename().string());
    std::sort(files.begin(), files.end());
    std::vector<std::string> moved;
    try {
        if (ec)
            throw io::WriteError(staging_, "cannot list the staged files (" + ec.message() + ")");
        for (const std::string& file : files) {
            fs::rename(staging_ / file, folder_ / file, ec);
            if (ec)
                throw io::WriteError(folder_ / file,
                                     "cannot move into place (" + ec.message() + ")");
            moved.push_back(file);
        }
        fs::remove_all(staging_, ec);
        WriteManifest(RunStatus::kComplete, files, "");
    } catch (const io::WriteError& e) {
        for (const std::string& file : moved) fs::remove_all(folder_ / file, ec);
        fs::remove_all(staging_, ec);
        try {
            WriteManifest(RunStatus::kFailed, {}, e.what());
        } catch (const std::exception&) {  // the first error is the one to report
        }
        finished_ = true;
        throw;
    }
    finished_ = true;
    return files;
}

void RunFolder::Abandon(RunStatus status, const std::string& message) noexcept {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    finished_ = true;
    std::error_code ec;
    fs::remove_all(staging_, ec);
    try {
        WriteManifest(status, {}, message);
    } catch (const std::exception&) {  // nothing left to tell: the folder holds no results
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
                              const std::string& message) const {
    nlohmann::json json;
    json["tool"] = "lidarloop";
    json["version"] = LIDARLOOP_VERSION;
    json["command_line"] = info_.command_line;
    json["status"] = ToString(status);
    json["started"] = started_;
    json["ended"] = UtcNow();
    json["files"] = files;
    if (!message.empty()) json["message"] = message;
    // Written beside, then renamed: run.json is whole or absent.
    const fs::path temporary = folder_ / (std::string(".") + kManifest + ".tmp");
    std::ofstream out(temporary);
    out << json.dump(2) << "\n";
    out.close();
    std::error_code ec;
    if (!out) {
        fs::remove(temporary, ec);
        throw io::WriteError(folder_ / kManifest, "writing failed (disk full?)");
    }
    fs::rename(temporary, folder_ / kManifest, ec);
    if (ec)
        throw io::WriteError(folder_ / kManifest, "cannot move into place (" + ec.message() + ")");
}

}  // namespace lidarloop::app

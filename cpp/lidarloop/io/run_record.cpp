#include "lidarloop/io/run_record.hpp"

#include <fstream>

#include <nlohmann/json.hpp>

#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {
namespace fs = std::filesystem;
namespace {

// A name run.json may list: a plain name in the folder, nothing that leads elsewhere.
bool IsPlainName(const std::string& name) {
    return !name.empty() && name != "." && name != ".." && fs::path(name).filename() == name;
}

std::vector<std::string> ListedFiles(const nlohmann::json& json) {
    std::vector<std::string> files;
    if (!json.contains("files") || !json["files"].is_array()) return files;
    for (const auto& file : json["files"]) {
        if (file.is_string() && IsPlainName(file.get<std::string>()))
            files.push_back(file.get<std::string>());
    }
    return files;
}

// A string field, or "" when it is missing or not a string (json::value would throw).
std::string StringField(const nlohmann::json& json, const char* key) {
    const auto found = json.find(key);
    return found != json.end() && found->is_string() ? found->get<std::string>() : std::string();
}

std::optional<RunRecord> ParseRecord(const fs::path& file) {
    std::ifstream in(file);
    if (!in) return std::nullopt;
    const nlohmann::json json = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (!json.is_object() || StringField(json, "tool") != "lidarloop") return std::nullopt;
    RunRecord record;
    record.kind = StringField(json, "kind") == "dataset" ? RunKind::kDataset : RunKind::kResults;
    record.status = StringField(json, "status");
    record.files = ListedFiles(json);
    record.command = StringField(json, "command");
    return record;
}

// simulate wrote simulation.yaml with this first line before it wrote run.json.
std::optional<RunRecord> LegacySimulation(const fs::path& folder) {
    std::ifstream in(folder / "simulation.yaml");
    std::string first_line;
    if (!in || !std::getline(in, first_line) || first_line.rfind("# lidarloop ", 0) != 0 ||
        first_line.find(" simulate:") == std::string::npos) {
        return std::nullopt;
    }
    return RunRecord{
        RunKind::kDataset,
        "complete",
        {"velodyne", "poses.txt", "times.txt", "poses_odometry.txt", "simulation.yaml"},
        "simulate"};
}

}  // namespace

std::string ToString(RunKind kind) { return kind == RunKind::kDataset ? "dataset" : "results"; }

std::optional<RunRecord> ReadRunRecord(const fs::path& folder) {
    std::error_code ec;
    if (fs::exists(folder / kRunRecordName, ec)) return ParseRecord(folder / kRunRecordName);
    return LegacySimulation(folder);
}

void RefuseIncompleteDataset(const fs::path& folder) {
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) return;
    const std::optional<RunRecord> record = ReadRunRecord(folder);
    if (!record || record->kind != RunKind::kDataset || record->status == "complete") return;
    throw ReadError(folder / kRunRecordName,
                    "the sequence here was not finished (status \"" + record->status +
                        "\"); write it again, e.g. with lidarloop simulate");
}

}  // namespace lidarloop::io

#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace lidarloop::io {

/// What a folder that lidarloop wrote holds: results of a run (detect, evaluate, optimise,
/// demo) or a dataset (simulate). A folder of one kind is never replaced by a run of the other
/// without --overwrite.
enum class RunKind { kResults, kDataset };

/// "results", "dataset".
std::string ToString(RunKind kind);

/// The record a lidarloop run leaves in its folder (run.json, docs/cli.md): the proof that
/// lidarloop wrote the files it lists.
struct RunRecord {
    RunKind kind = RunKind::kResults;
    std::string status;              ///< complete, failed, interrupted
    std::vector<std::string> files;  ///< plain names in the folder, files or subfolders
    std::string command = {};        ///< detect, evaluate, ...; empty when not recorded
};

/// run.json, the record's name in its folder.
inline constexpr char kRunRecordName[] = "run.json";

/// The record in `folder`; nullopt when it holds none that lidarloop wrote. A sequence that
/// `simulate` wrote before run.json existed (its simulation.yaml says so) counts as a complete
/// dataset. Never throws for a foreign or corrupt run.json (that is no record).
std::optional<RunRecord> ReadRunRecord(const std::filesystem::path& folder);

/// Throws ReadError when `folder` holds a dataset that lidarloop began but did not finish
/// (`simulate` failed or was interrupted): its scans would be read with missing poses.
void RefuseIncompleteDataset(const std::filesystem::path& folder);

}  // namespace lidarloop::io

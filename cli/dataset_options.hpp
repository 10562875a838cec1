#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "lidarloop/io/dataset.hpp"

namespace lidarloop::cli {

/// DATASET and the flags that say how to open it, shared by the commands that read sequences.
class DatasetOptions {
public:
    /// Adds the DATASET positional and --format, --poses, --calib, --topic; `format_flag` renames
    /// --format for a command whose --format means something else (optimise's pose format);
    /// without `with_poses` no --poses and --calib (a command whose --poses means another thing).
    void AddTo(CLI::App& command, const std::string& format_flag = "--format",
               bool with_poses = true);
    io::Dataset Open() const;
    /// The folder and the files given for it, which no output may lie inside or replace.
    std::vector<std::filesystem::path> Inputs() const { return {path_, poses_, calib_}; }
    const std::string& path() const { return path_; }

private:
    std::string path_;
    std::string format_ = "auto";
    std::string poses_;
    std::string calib_;
    std::string topic_;
};

}  // namespace lidarloop::cli

#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace lidarloop::cli {

/// --odometry FILE and --odometry-topic TOPIC (for a bag), one excluding the other, and
/// --odometry-calib for a KITTI file in KITTI's camera frame: the flags of every command that
/// reads a sequence's odometry.
class OdometryOptions {
public:
    /// `use` says what the command does with the odometry (the end of --odometry's help).
    void AddTo(CLI::App& command, const std::string& use);
    const std::string& file() const { return file_; }
    const std::string& topic() const { return topic_; }
    const std::string& calib() const { return calib_; }
    bool given() const { return !file_.empty() || !topic_.empty(); }
    /// The files given, which no output may lie inside or replace (empty paths when none).
    std::vector<std::filesystem::path> Inputs() const { return {file_, calib_}; }

private:
    std::string file_;
    std::string topic_;
    std::string calib_;
};

}  // namespace lidarloop::cli

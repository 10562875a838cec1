#pragma once

#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

namespace lidarloop::cli {

/// --odometry FILE and --odometry-topic TOPIC (for a bag), one excluding the other: the flags
/// of every command that reads a sequence's odometry.
class OdometryOptions {
public:
    /// `use` says what the command does with the odometry (the end of --odometry's help).
    void AddTo(CLI::App& command, const std::string& use);
    const std::string& file() const { return file_; }
    const std::string& topic() const { return topic_; }
    bool given() const { return !file_.empty() || !topic_.empty(); }
    /// The file given, which no output may lie inside or replace (empty when none).
    std::filesystem::path Input() const { return file_; }

private:
    std::string file_;
    std::string topic_;
};

}  // namespace lidarloop::cli

#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "lidarloop/io/config_yaml.hpp"

namespace lidarloop::cli {

/// The detection flags, declared and applied in one place for every command that takes them:
/// --min-gap and --min-gap-unit always, --threshold, --top-k and --no-verify where a command
/// decides loops.
class DetectionOptions {
public:
    /// `min_gap_help` says what the gap means to the command.
    void AddTo(CLI::App& command, bool decides_loops, const std::string& min_gap_help);
    /// Overrides the keys the given flags name and validates `config`.
    void ApplyTo(io::RunConfig& config) const;

private:
    double threshold_ = 0.0;
    double min_gap_ = 0.0;
    std::string min_gap_unit_;
    int top_k_ = 0;
    bool no_verify_ = false;
    CLI::Option* threshold_option_ = nullptr;
    CLI::Option* min_gap_option_ = nullptr;
    CLI::Option* top_k_option_ = nullptr;
};

}  // namespace lidarloop::cli

#pragma once

#include <deque>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::cli {

/// The flags that choose and tune a descriptor, shared by every subcommand that computes one.
/// Precedence: built-in defaults < --config FILE < individual flags.
class DescriptorOptions {
public:
    /// Adds --config, --method and a flag per declared parameter (docs/options.md): the
    /// histogram's keep their short names (--bins, --min, --max, --up, --sensor-height,
    /// --out-of-range), the other sections' are --<section>-<key> (--ndt-cell-size-m,
    /// --scancontext-rings, ...).
    void AddTo(CLI::App& command, bool with_method = true);

    /// The effective configuration: `base` (default: the built-in defaults) with --config and
    /// the flags applied; throws core::Error (or io::ReadError) when it is invalid.
    io::RunConfig Resolve(io::RunConfig base = {}) const;
    /// The first descriptor flag given on the command line ("--bins", ...), or "" when none.
    std::string FirstGiven() const;
    /// The --config file ("" when none): an input, never to be replaced by a run's output.
    const std::string& config_file() const { return config_file_; }
    /// Whether --min or --max was given: they set the value range of one projection.
    bool GivesValueRange() const { return *min_option_ || *max_option_; }

    /// A flag of a declared parameter, kept as given and applied through the YAML reader, so
    /// that its value is read and checked exactly as the key in a file.
    struct ParameterFlag {
        std::string section;                ///< its YAML section
        std::vector<core::Method> methods;  ///< the methods it applies to
        std::string key;                    ///< its YAML key
        std::string range_key;              ///< --min, --max: the key for the range projection
        std::string value;
        CLI::Option* option = nullptr;
    };

private:
    void AddSectionFlags(CLI::App& command, const pipeline::ParameterSection& section);
    void CheckApplies(const ParameterFlag& flag, const core::Method& method) const;
    void ApplyFlags(io::RunConfig& config) const;

    std::string config_file_;
    std::string method_;
    bool with_method_ = true;  // false: the command runs several methods (evaluate)
    const CLI::Option* min_option_ = nullptr;
    const CLI::Option* max_option_ = nullptr;
    std::deque<ParameterFlag> flags_;  // a deque: CLI11 keeps the address of each value
};

}  // namespace lidarloop::cli

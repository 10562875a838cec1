#pragma once

#include <array>
#include <deque>
#include <string>

#include <CLI/CLI.hpp>

#include "lidarloop/io/config_yaml.hpp"

namespace lidarloop::cli {

/// The flags that choose and tune a descriptor, shared by every subcommand that computes one.
/// Precedence: built-in defaults < --config FILE < individual flags.
class DescriptorOptions {
public:
    /// Adds --config, --method, the histogram flags --bins, --min, --max, --up,
    /// --sensor-height, --out-of-range (NDT parameters come from --config), and a flag per
    /// declared parameter of every registered method that has its own (--scancontext-rings ...;
    /// docs/options.md).
    void AddTo(CLI::App& command, bool with_method = true);

    /// The effective configuration: `base` (default: the built-in defaults) with --config and
    /// the flags applied; throws core::Error (or io::ReadError) when it is invalid.
    io::RunConfig Resolve(io::RunConfig base = {}) const;
    /// The first descriptor flag given on the command line ("--bins", ...), or "" when none.
    std::string FirstGiven() const;
    /// Whether --min or --max was given: they set the value range of one projection.
    bool GivesValueRange() const { return *min_option_ || *max_option_; }

    /// A flag of a registered method's parameter, kept as given and applied through the YAML
    /// reader, so that its value is read and checked exactly as the key in a file.
    struct MethodFlag {
        std::string section;  ///< the method's name
        std::string key;      ///< the parameter's YAML key
        std::string value;
        CLI::Option* option = nullptr;
    };

private:
    void ApplyHistogramFlags(core::DescriptorConfig& descriptor) const;
    void ApplyMethodFlags(io::RunConfig& config) const;
    /// --bins, --min, --max, --up, --sensor-height, --out-of-range.
    std::array<const CLI::Option*, 6> HistogramFlags() const {
        return {bins_option_, min_option_,           max_option_,
                up_option_,   sensor_height_option_, out_of_range_option_};
    }

    std::string config_file_;
    std::string method_;
    bool with_method_ = true;  // false: the command runs several methods (evaluate)
    int bins_ = 0;
    double min_m_ = 0.0;
    double max_m_ = 0.0;
    std::string up_;
    double sensor_height_m_ = 0.0;
    std::string out_of_range_;
    CLI::Option* bins_option_ = nullptr;
    CLI::Option* min_option_ = nullptr;
    CLI::Option* max_option_ = nullptr;
    CLI::Option* sensor_height_option_ = nullptr;
    CLI::Option* up_option_ = nullptr;
    CLI::Option* out_of_range_option_ = nullptr;
    std::deque<MethodFlag> method_flags_;  // a deque: CLI11 keeps the address of each value
};

}  // namespace lidarloop::cli

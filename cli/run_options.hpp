#pragma once

#include <deque>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "lidarloop/app/run_options.hpp"

namespace lidarloop::cli {

/// The declared run options of one command (app/run_options.hpp) as its flags, added and applied
/// in one place for detect, evaluate, optimise and bench.
class RunOptionFlags {
public:
    void AddTo(CLI::App& command, app::RunCommand which);
    /// Applies the flags given, in declaration order, and validates the config.
    void ApplyTo(const app::RunTargets& targets) const;

private:
    struct Slot {
        const app::RunOption* option = nullptr;
        int integer = 0;
        double number = 0.0;
        std::string name;
        std::vector<double> numbers;
        bool on = false;
        CLI::Option* flag = nullptr;
    };
    std::deque<Slot> slots_;  // a deque: CLI11 keeps the address of each value
};

}  // namespace lidarloop::cli

#pragma once

// The options of the run commands that the `lidarloop` tool and the Python package both take,
// declared once (docs/options.md): the CLI's flags (cli/run_options.cpp), the Python keywords and
// the call text run.json records (python/src/bind_app.cpp), and docs/cli.md's table of run options
// (`lidarloop dump-config --markdown-run-options`) all come from RunOptions().

#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/io/config_yaml.hpp"

namespace lidarloop::app {

/// The commands with declared run options.
enum class RunCommand : std::uint8_t { kDetect = 1, kEvaluate = 2, kOptimise = 4, kBench = 8 };

/// The name of a command as typed ("detect"); RunCommandOf: the inverse, ConfigError otherwise.
std::string_view NameOf(RunCommand command);
RunCommand RunCommandOf(std::string_view name);

/// What an option takes.
enum class RunOptionType : std::uint8_t {
    kInt,
    kNumber,
    kName,
    kNumbers,    ///< a list: the flag takes T,T,... ; the keyword a list of numbers
    kSwitch,     ///< the flag takes no value and sets true; the keyword a bool
    kSwitchOff,  ///< the flag (--no-verify) takes no value and sets false; the keyword a bool
};

using RunOptionValue = std::variant<bool, int, double, std::string, std::vector<double>>;

/// What a run option sets: the run's config, its skip_bad, and for evaluate the request.
struct RunTargets {
    io::RunConfig* config = nullptr;
    bool* skip_bad = nullptr;
    EvaluationRequest* evaluation = nullptr;  ///< evaluate only
};

/// One run option, declared once.
struct RunOption {
    std::string_view keyword;     ///< Python keyword ("top_k")
    std::string_view flag;        ///< flag ("--top-k")
    std::string_view value_name;  ///< in --help and the docs ("K"); empty for switches
    RunOptionType type;
    std::string_view help;  ///< one line: --help, the docs
    std::string_view sets;  ///< what it sets, for the docs ("detection.top_k")
    std::uint8_t commands;  ///< RunCommand bits
    /// Sets the value (of `type`'s alternative) into `targets`; ConfigError for a bad name.
    void (*apply)(const RunTargets& targets, const RunOptionValue& value);
    /// The default, as the docs show it (from the default config and request).
    std::string (*default_text)();

    bool TakenBy(RunCommand command) const {
        return (commands & static_cast<std::uint8_t>(command)) != 0;
    }
};

/// Every run option, in the order --help, the keywords and the docs list them.
const std::vector<RunOption>& RunOptions();
/// The options `command` takes, in that order.
std::vector<const RunOption*> RunOptionsOf(RunCommand command);

/// Applies `value` (of the option's type) and validates the config (valid before: what is wrong
/// then is this option's); core::ConfigError naming the option (its keyword when `by_keyword`,
/// else its flag) when the value is invalid.
void ApplyRunOption(const RunOption& option, const RunOptionValue& value, const RunTargets& targets,
                    bool by_keyword);

/// docs/cli.md's table of run options: flag, keyword, commands, what it sets and its default,
/// and the help.
std::string RunOptionsMarkdown();

}  // namespace lidarloop::app

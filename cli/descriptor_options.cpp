#include "descriptor_options.hpp"

#include <algorithm>
#include <charconv>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::cli {
namespace {

// A default as the help shows it.
template <typename T>
std::string DefaultText(const T& value) {
    if constexpr (std::is_same_v<T, bool>) {
        return value ? "true" : "false";
    } else if constexpr (std::is_same_v<T, std::string>) {
        return value;
    } else if constexpr (std::is_same_v<T, std::optional<double>>) {
        return value ? DefaultText(*value) : "default";
    } else if constexpr (std::is_same_v<T, std::vector<double>>) {
        std::string text = "[";
        for (const double v : value) text += (text.size() > 1 ? ", " : "") + DefaultText(v);
        return text + "]";
    } else {
        char buffer[64];
        const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
        return std::string(buffer, result.ptr);
    }
}

template <typename T>
const char* TypeName() {
    if constexpr (std::is_same_v<T, bool>) return "BOOL";
    if constexpr (std::is_integral_v<T>) return "INT";
    if constexpr (std::is_same_v<T, std::string>) return "NAME";
    if constexpr (std::is_same_v<T, std::vector<double>>) return "[FLOAT,...]";
    return "FLOAT";
}

// The histogram's flags predate the declarations and keep their short names. --min and --max
// set the value range of the projection in use: the height's with --method height, else the
// range's, whose keys therefore have no flag of their own. A histogram key not listed here gets
// --histogram-<key>.
struct ShortFlag {
    std::string_view key;
    std::string_view name;
    std::string_view range_key;  // --min, --max: the key for the range projection
    std::string_view help;       // "": the declared one
    bool height_only;
};
constexpr ShortFlag kShortFlags[] = {
    {"bins", "--bins", "", "", false},
    {"up_vector", "--up", "", "", true},
    {"sensor_height_m", "--sensor-height", "", "", true},
    {"height_min_m", "--min", "range_min_m", "v_min of the projection in use", false},
    {"height_max_m", "--max", "range_max_m", "v_max of the projection in use", false},
    {"out_of_range", "--out-of-range", "", "", false},
};

// The short flag of histogram key `key`, or nullptr; `covered` is set for a key that --min or
// --max sets.
const ShortFlag* ShortFlagOf(std::string_view key, bool& covered) {
    covered = false;
    for (const ShortFlag& flag : kShortFlags) {
        if (flag.key == key) return &flag;
        covered = covered || flag.range_key == key;
    }
    return nullptr;
}

// Adds a flag for each declared parameter it visits: --<section>-<key> (underscores become
// hyphens), or the histogram's short one.
class FlagAdder final : public core::ParameterVisitor {
public:
    FlagAdder(CLI::App& command, const pipeline::ParameterSection& section, std::string group,
              std::deque<DescriptorOptions::ParameterFlag>& flags)
        : command_(command), section_(section), group_(std::move(group)), flags_(flags) {}
    void Visit(const core::ParameterInfo& i, bool& value) override { Add(i, value); }
    void Visit(const core::ParameterInfo& i, int& value) override { Add(i, value); }
    void Visit(const core::ParameterInfo& i, std::size_t& value) override { Add(i, value); }
    void Visit(const core::ParameterInfo& i, double& value) override { Add(i, value); }
    void Visit(const core::ParameterInfo& i, std::optional<double>& value) override {
        Add(i, value);
    }
    void Visit(const core::ParameterInfo& i, std::vector<double>& value) override { Add(i, value); }
    void Visit(const core::ParameterInfo& i, std::string& value) override { Add(i, value); }

private:
    template <typename T>
    void Add(const core::ParameterInfo& info, const T& default_value) {
        DescriptorOptions::ParameterFlag flag{
            section_.name, section_.methods, std::string(info.key), "", "", nullptr};
        std::string name = "--" + section_.name + "-" + flag.key;
        std::replace(name.begin() + 2, name.end(), '_', '-');
        std::string help = Help(info, default_value);
        bool covered = false;
        const ShortFlag* short_flag = section_.name == core::HistogramConfig::kSection
                                          ? ShortFlagOf(info.key, covered)
                                          : nullptr;
        if (covered) return;
        if (short_flag != nullptr) {
            name = short_flag->name;
            if (short_flag->height_only) flag.methods = {core::Method::kHeight};
            flag.range_key = short_flag->range_key;
            if (!short_flag->help.empty()) {
                help = std::string(short_flag->help) + " (histogram." + flag.key + " or " +
                       flag.range_key + ", " + std::string(info.unit) + ")";
            }
        }
        DescriptorOptions::ParameterFlag& added = flags_.emplace_back(std::move(flag));
        added.option =
            command_.add_option(name, added.value, help)->type_name(TypeName<T>())->group(group_);
    }
    // The declared help with the unit, the range and the default.
    template <typename T>
    static std::string Help(const core::ParameterInfo& info, const T& default_value) {
        std::string help = std::string(info.help) + " (";
        if (!info.unit.empty()) help += std::string(info.unit) + ", ";
        if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
            if (info.HasRange()) help += core::RangeText<T>(info, " to ") + ", ";
        }
        return help + "default " + DefaultText(default_value) + ")";
    }
    CLI::App& command_;
    const pipeline::ParameterSection& section_;
    std::string group_;
    std::deque<DescriptorOptions::ParameterFlag>& flags_;
};

// A flag's value as a YAML scalar: quoted, so that no character of it is YAML syntax, except a
// list ([3, 6]), which stays a flow sequence.
std::string YamlValue(const std::string& value) {
    if (!value.empty() && value.front() == '[') return value;
    std::string quoted = "'";
    for (const char c : value) quoted += c == '\'' ? std::string("''") : std::string(1, c);
    return quoted + "'";
}

}  // namespace

void DescriptorOptions::AddTo(CLI::App& command, bool with_method) {
    command.add_option("--config", config_file_, "YAML file overriding the defaults it names")
        ->check(CLI::ExistingFile);
    with_method_ = with_method;
    if (with_method) {
        command.add_option("--method", method_, "descriptor: " + pipeline::MethodNamesText(" | "));
    }
    for (const pipeline::ParameterSection& section :
         pipeline::ParameterSectionsOf(core::DescriptorConfig{})) {
        AddSectionFlags(command, section);
    }
    min_option_ = command.get_option("--min");
    max_option_ = command.get_option("--max");
}

void DescriptorOptions::AddSectionFlags(CLI::App& command,
                                        const pipeline::ParameterSection& section) {
    std::string methods;
    for (const core::Method& method : section.methods)
        methods += (methods.empty() ? "" : " or ") + core::ToString(method);
    const std::string group =
        section.name + " parameters" + (with_method_ ? " (with --method " + methods + ")" : "");
    FlagAdder adder(command, section, group, flags_);
    section.visit(adder);
}

io::RunConfig DescriptorOptions::Resolve(io::RunConfig base) const {
    io::RunConfig config = std::move(base);
    if (!config_file_.empty()) config = io::LoadConfigYaml(config_file_, config);
    if (!method_.empty()) config.descriptor.method = pipeline::ParseMethod(method_);
    ApplyFlags(config);
    config.Validate();
    return config;
}

std::string DescriptorOptions::FirstGiven() const {
    if (!config_file_.empty()) return "--config";
    if (!method_.empty()) return "--method";
    for (const ParameterFlag& flag : flags_) {
        if (*flag.option) return flag.option->get_name();
    }
    return "";
}

void DescriptorOptions::CheckApplies(const ParameterFlag& flag, const core::Method& method) const {
    const std::string name = flag.option->get_name();
    if (flag.section == core::HistogramConfig::kSection && !core::IsHistogramMethod(method)) {
        throw core::ConfigError(name + " applies to the height and range methods, not " +
                                core::ToString(method) + ": its parameters have flags --" +
                                core::ToString(method) + "-... (--help)");
    }
    const auto& methods = flag.methods;
    if (!with_method_ || std::find(methods.begin(), methods.end(), method) != methods.end()) return;
    const std::string wanted = core::ToString(methods.front());  // a section's other methods
    throw core::ConfigError(name + " applies to the " + wanted + " method" +
                            (flag.section != wanted ? " only" : "") + ": add --method " + wanted);
}

// The given flags as the keys of one YAML text, in the order declared: read, checked and
// validated exactly as those keys in a --config file (together, so that --min 8 --max 10 is
// checked as a pair), the flags named as the source of an error.
void DescriptorOptions::ApplyFlags(io::RunConfig& config) const {
    const core::Method& method = config.descriptor.method;
    std::string yaml;
    std::string given;
    const std::string* section = nullptr;
    for (const ParameterFlag& flag : flags_) {
        if (!*flag.option) continue;
        CheckApplies(flag, method);
        if (section == nullptr || *section != flag.section) yaml += flag.section + ":\n";
        section = &flag.section;
        const bool range = !flag.range_key.empty() && method != core::Method::kHeight;
        yaml += "  " + (range ? flag.range_key : flag.key) + ": " + YamlValue(flag.value) + "\n";
        given += (given.empty() ? "" : ", ") + flag.option->get_name();
    }
    if (!given.empty()) io::ApplyConfigYaml(yaml, given, config);
}

}  // namespace lidarloop::cli

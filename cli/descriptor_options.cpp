#include "descriptor_options.hpp"

#include <algorithm>
#include <charconv>
#include <optional>
#include <string>
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

// Adds --<section>-<key> for each declared parameter it visits (underscores become hyphens).
class FlagAdder final : public core::ParameterVisitor {
public:
    FlagAdder(CLI::App& command, std::string section, std::string group,
              std::deque<DescriptorOptions::MethodFlag>& flags)
        : command_(command),
          section_(std::move(section)),
          group_(std::move(group)),
          flags_(flags) {}
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
        std::string name = "--" + section_ + "-" + std::string(info.key);
        std::replace(name.begin() + 2, name.end(), '_', '-');
        std::string help = std::string(info.help) + " (";
        if (!info.unit.empty()) help += std::string(info.unit) + ", ";
        if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
            if (info.HasRange()) {
                help += DefaultText(static_cast<T>(info.min)) + " to " +
                        DefaultText(static_cast<T>(info.max)) + ", ";
            }
        }
        help += "default " + DefaultText(default_value) + ")";
        DescriptorOptions::MethodFlag& flag = flags_.emplace_back(
            DescriptorOptions::MethodFlag{section_, std::string(info.key), {}, nullptr});
        flag.option =
            command_.add_option(name, flag.value, help)->type_name(TypeName<T>())->group(group_);
    }
    CLI::App& command_;
    std::string section_;
    std::string group_;
    std::deque<DescriptorOptions::MethodFlag>& flags_;
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
    bins_option_ = command.add_option("--bins", bins_, "number of histogram buckets b");
    min_option_ = command.add_option("--min", min_m_, "v_min of the chosen projection, metres");
    max_option_ = command.add_option("--max", max_m_, "v_max of the chosen projection, metres");
    up_option_ = command.add_option("--up", up_, "up vector of the height projection: fixed | pca");
    sensor_height_option_ = command.add_option("--sensor-height", sensor_height_m_,
                                               "sensor height above ground, metres");
    out_of_range_option_ = command.add_option("--out-of-range", out_of_range_,
                                              "values outside [min, max]: clamp | drop");
    for (core::MethodParameters& p : pipeline::MethodParametersOf(core::DescriptorConfig{})) {
        const std::string group = p.section() + " parameters" +
                                  (with_method ? " (with --method " + p.section() + ")" : "");
        FlagAdder adder(command, p.section(), group, method_flags_);
        p.Visit(adder);
    }
}

io::RunConfig DescriptorOptions::Resolve(io::RunConfig base) const {
    io::RunConfig config = std::move(base);
    if (!config_file_.empty()) config = io::LoadConfigYaml(config_file_, config);
    if (!method_.empty()) config.descriptor.method = pipeline::ParseMethod(method_);
    ApplyHistogramFlags(config.descriptor);
    ApplyMethodFlags(config);
    config.Validate();
    return config;
}

std::string DescriptorOptions::FirstGiven() const {
    if (!config_file_.empty()) return "--config";
    if (!method_.empty()) return "--method";
    for (const CLI::Option* flag : HistogramFlags()) {
        if (*flag) return flag->get_name();
    }
    for (const MethodFlag& flag : method_flags_) {
        if (*flag.option) return flag.option->get_name();
    }
    return "";
}

// Each given flag as the one key of a YAML text, in the order declared: read, checked and
// validated exactly as that key in a --config file, the flag named as the source of an error.
void DescriptorOptions::ApplyMethodFlags(io::RunConfig& config) const {
    for (const MethodFlag& flag : method_flags_) {
        if (!*flag.option) continue;
        if (with_method_ && core::ToString(config.descriptor.method) != flag.section) {
            throw core::ConfigError(flag.option->get_name() + " applies to the " + flag.section +
                                    " method: add --method " + flag.section);
        }
        io::ApplyConfigYaml(flag.section + ":\n  " + flag.key + ": " + YamlValue(flag.value) + "\n",
                            flag.option->get_name(), config);
    }
}

void DescriptorOptions::ApplyHistogramFlags(core::DescriptorConfig& descriptor) const {
    for (const CLI::Option* flag : HistogramFlags()) {
        if (*flag && !core::IsHistogramMethod(descriptor.method)) {
            throw core::ConfigError(flag->get_name() +
                                    " applies to the height and range methods; set the "
                                    "parameters of " +
                                    core::ToString(descriptor.method) +
                                    " in its section of --config");
        }
    }
    for (const CLI::Option* flag : {up_option_, sensor_height_option_}) {
        if (*flag && with_method_ && descriptor.method != core::Method::kHeight) {
            throw core::ConfigError(flag->get_name() +
                                    " applies to the height method only: add --method height");
        }
    }
    core::HistogramConfig& histogram = descriptor.histogram;
    if (*bins_option_) histogram.bins = bins_;
    if (*up_option_) histogram.up_vector = core::ParseUpVectorMode(up_);
    if (*sensor_height_option_) histogram.sensor_height_m = sensor_height_m_;
    if (*out_of_range_option_) histogram.out_of_range = core::ParseOutOfRangePolicy(out_of_range_);
    // --min/--max set the value range of the projection in use.
    const bool height = descriptor.method == core::Method::kHeight;
    if (*min_option_) (height ? histogram.height_min_m : histogram.range_min_m) = min_m_;
    if (*max_option_) (height ? histogram.height_max_m : histogram.range_max_m) = max_m_;
}

}  // namespace lidarloop::cli

#include "descriptor_options.hpp"

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::cli {

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
}

io::RunConfig DescriptorOptions::Resolve(io::RunConfig base) const {
    io::RunConfig config = std::move(base);
    if (!config_file_.empty()) config = io::LoadConfigYaml(config_file_, config);
    if (!method_.empty()) config.descriptor.method = pipeline::ParseMethod(method_);
    ApplyHistogramFlags(config.descriptor);
    config.Validate();
    return config;
}

std::string DescriptorOptions::FirstGiven() const {
    if (!config_file_.empty()) return "--config";
    if (!method_.empty()) return "--method";
    for (const CLI::Option* flag : HistogramFlags()) {
        if (*flag) return flag->get_name();
    }
    return "";
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

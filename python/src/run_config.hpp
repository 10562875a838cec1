#pragma once

// The configuration of a Python call, built like the CLI's: defaults < `config` (a dict or a
// YAML file) < method < the histogram keywords (cli/descriptor_options.cpp does the same for
// flags).

#include <optional>
#include <string>

#include <pybind11/pybind11.h>

#include "conversions.hpp"
#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::python {

/// The histogram keywords of describe(), as the flags --bins --min --max --up --sensor-height
/// --out-of-range of `lidarloop describe`; unset ones keep the config's value.
struct HistogramKeywords {
    std::optional<int> bins;
    std::optional<double> min_m;
    std::optional<double> max_m;
    std::optional<std::string> up;
    std::optional<double> sensor_height_m;
    std::optional<std::string> out_of_range;

    bool any() const { return bins || min_m || max_m || up || sensor_height_m || out_of_range; }
};

inline void ApplyHistogramKeywords(const HistogramKeywords& keywords,
                                   core::DescriptorConfig& descriptor) {
    if (keywords.any() && !core::IsHistogramMethod(descriptor.method)) {
        const std::string method = core::ToString(descriptor.method);
        throw core::ConfigError(
            "bins, min, max, up, sensor_height and out_of_range apply to the height and range "
            "methods; give the parameters of " +
            method + " as its keywords (lidarloop.method_parameters('" + method + "'))");
    }
    if ((keywords.up || keywords.sensor_height_m) && descriptor.method != core::Method::kHeight) {
        throw core::ConfigError(
            "up and sensor_height apply to the height method only: pass method='height'");
    }
    core::HistogramConfig& histogram = descriptor.histogram;
    if (keywords.bins) histogram.bins = *keywords.bins;
    if (keywords.up) histogram.up_vector = core::ParseUpVectorMode(*keywords.up);
    if (keywords.sensor_height_m) histogram.sensor_height_m = *keywords.sensor_height_m;
    if (keywords.out_of_range) {
        histogram.out_of_range = core::ParseOutOfRangePolicy(*keywords.out_of_range);
    }
    // min and max set the value range of the projection in use, as --min and --max do.
    const bool height = descriptor.method == core::Method::kHeight;
    if (keywords.min_m) (height ? histogram.height_min_m : histogram.range_min_m) = *keywords.min_m;
    if (keywords.max_m) (height ? histogram.height_max_m : histogram.range_max_m) = *keywords.max_m;
}

/// RunConfigFrom(config), then `method` (a registered name) and the histogram keywords,
/// validated (lidarloop.ConfigError naming the first invalid field).
inline io::RunConfig ResolveRunConfig(const py::object& config,
                                      const std::optional<std::string>& method,
                                      const HistogramKeywords& keywords = {}) {
    io::RunConfig run = RunConfigFrom(config);
    if (method) run.descriptor.method = pipeline::ParseMethod(*method);
    ApplyHistogramKeywords(keywords, run.descriptor);
    run.Validate();
    return run;
}

}  // namespace lidarloop::python

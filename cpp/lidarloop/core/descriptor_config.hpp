#pragma once

#include <string>
#include <string_view>

#include "lidarloop/core/histogram.hpp"
#include "lidarloop/core/ndt_config.hpp"

namespace lidarloop::core {

/// Place descriptors lidarloop can compute.
enum class Method {
    kHeight,  ///< Röhling 2015 histogram of heights above the ground plane
    kRange,   ///< Röhling 2015 histogram of ranges
    kNdt,     ///< Magnusson 2009 NDT appearance descriptor
};

std::string ToString(Method method);
/// Parses "height" / "range" / "ndt"; throws ConfigError listing the valid names.
Method ParseMethod(std::string_view name);

/// True for the methods built on Röhling's histograms (height, range).
bool IsHistogramMethod(Method method);

/// The projection a histogram method uses; throws ConfigError for kNdt.
Projection ProjectionOf(Method method);

/// Everything that decides how a scan becomes a descriptor, and nothing else: two equal configs
/// give comparable descriptors. The single home of the descriptor defaults.
struct DescriptorConfig {
    Method method = Method::kHeight;
    HistogramConfig histogram;
    NdtConfig ndt;

    /// Throws ConfigError naming the first invalid field.
    void Validate() const {
        histogram.Validate();
        ndt.Validate();
    }
    bool operator==(const DescriptorConfig&) const = default;
};

}  // namespace lidarloop::core

#pragma once

#include <string>
#include <string_view>

#include "lidarloop/core/histogram.hpp"

namespace lidarloop::core {

/// Place descriptors lidarloop can compute.
enum class Method {
    kHeight,  ///< Röhling 2015 histogram of heights above the ground plane
    kRange,   ///< Röhling 2015 histogram of ranges
};

std::string ToString(Method method);
/// Parses "height" / "range"; throws ConfigError listing the valid names.
Method ParseMethod(std::string_view name);

/// The projection a histogram method uses.
Projection ProjectionOf(Method method);

/// Everything that decides how a scan becomes a descriptor. The single home of the defaults.
struct DescriptorConfig {
    Method method = Method::kHeight;
    HistogramConfig histogram;

    /// Throws ConfigError naming the first invalid field.
    void Validate() const { histogram.Validate(); }
};

}  // namespace lidarloop::core

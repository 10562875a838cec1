#include "lidarloop/core/descriptor_config.hpp"

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {

bool IsHistogramMethod(const Method& method) {
    return method == Method::kHeight || method == Method::kRange;
}

Projection ProjectionOf(const Method& method) {
    if (method == Method::kHeight) return Projection::kHeight;
    if (method == Method::kRange) return Projection::kRange;
    throw ConfigError("method '" + ToString(method) + "' is not a histogram projection");
}

}  // namespace lidarloop::core

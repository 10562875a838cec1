#include "lidarloop/core/descriptor_config.hpp"

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {

std::string ToString(Method method) { return method == Method::kHeight ? "height" : "range"; }

Method ParseMethod(std::string_view name) {
    if (name == "height") return Method::kHeight;
    if (name == "range") return Method::kRange;
    throw ConfigError("unknown method '" + std::string(name) + "' (valid: height, range)");
}

Projection ProjectionOf(Method method) {
    return method == Method::kHeight ? Projection::kHeight : Projection::kRange;
}

}  // namespace lidarloop::core

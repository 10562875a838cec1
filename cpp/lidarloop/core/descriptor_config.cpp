#include "lidarloop/core/descriptor_config.hpp"

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {

std::string ToString(Method method) {
    switch (method) {
        case Method::kHeight:
            return "height";
        case Method::kRange:
            return "range";
        case Method::kNdt:
            return "ndt";
    }
    return "unknown";
}

Method ParseMethod(std::string_view name) {
    if (name == "height") return Method::kHeight;
    if (name == "range") return Method::kRange;
    if (name == "ndt") return Method::kNdt;
    throw ConfigError("unknown method '" + std::string(name) + "' (valid: height, range, ndt)");
}

bool IsHistogramMethod(Method method) { return method != Method::kNdt; }

Projection ProjectionOf(Method method) {
    if (method == Method::kHeight) return Projection::kHeight;
    if (method == Method::kRange) return Projection::kRange;
    throw ConfigError("method '" + ToString(method) + "' is not a histogram projection");
}

}  // namespace lidarloop::core

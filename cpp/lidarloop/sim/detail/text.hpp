#pragma once

// Internal: numbers in error messages. Not installed.

#include <charconv>
#include <string>

namespace lidarloop::sim::detail {

/// The shortest text that reads back as `value` ("0.02", "1e+06", "nan").
inline std::string NumberText(double value) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return std::string(buffer, result.ptr);
}

}  // namespace lidarloop::sim::detail

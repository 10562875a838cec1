#pragma once

// Numbers in messages and written parameters.

#include <charconv>
#include <string>

namespace lidarloop::core {

/// The shortest text that reads back as `value` ("0.02", "1e+06", "nan").
inline std::string NumberText(double value) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return std::string(buffer, result.ptr);
}

}  // namespace lidarloop::core

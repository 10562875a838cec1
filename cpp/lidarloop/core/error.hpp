#pragma once

#include <cstddef>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <string_view>

namespace lidarloop::core {

/// Base of every exception lidarloop throws on purpose; `what()` is one readable line.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A configuration value is out of its valid range or inconsistent with another value.
class ConfigError : public Error {
public:
    using Error::Error;
};

/// Encoded data (a saved database, a similarity matrix) is damaged or not what it claims.
class FormatError : public Error {
public:
    using Error::Error;
};

/// The input holds no usable data (empty scan, every point non-finite or out of range).
class EmptyInputError : public Error {
public:
    using Error::Error;
};

/// `token` (a piece of input: a field, a key, a value) in single quotes for an error message,
/// cut to its first kQuotedMaxChars bytes and followed by its length when longer, so that one huge
/// token cannot make a huge message: 'abc', or 'abc...' (52428800 characters). Control characters
/// are written as \xNN so that the message stays one line.
inline std::string Quoted(std::string_view token) {
    constexpr std::size_t kQuotedMaxChars = 40;
    std::size_t shown = token.size();
    if (shown > kQuotedMaxChars) {
        shown = kQuotedMaxChars;
        // Cut before a UTF-8 continuation byte, not inside a character.
        while (shown > 0 && (static_cast<unsigned char>(token[shown]) & 0xC0) == 0x80) --shown;
    }
    std::string quoted = "'";
    for (const char c : token.substr(0, shown)) {
        const auto code = static_cast<unsigned char>(c);
        if (code >= 0x20 && code != 0x7f) {
            quoted += c;
            continue;
        }
        char escaped[8];
        std::snprintf(escaped, sizeof(escaped), "\\x%02x", code);
        quoted += escaped;
    }
    if (shown == token.size()) return quoted + "'";
    return quoted + "...' (" + std::to_string(token.size()) + " characters)";
}

}  // namespace lidarloop::core

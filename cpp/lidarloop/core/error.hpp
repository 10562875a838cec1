#pragma once

#include <stdexcept>
#include <string>

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

}  // namespace lidarloop::core

#pragma once

#include <filesystem>
#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::io {

/// A file could not be read or parsed. `what()` is "<file>: <problem>" on one line, and names the
/// line or field where that helps ("line 12: expected 3 numbers, got 2").
class ReadError : public core::Error {
public:
    ReadError(const std::filesystem::path& file, const std::string& problem)
        : core::Error(file.string() + ": " + problem), file_(file) {}

    const std::filesystem::path& file() const { return file_; }

private:
    std::filesystem::path file_;
};

/// A file could not be written.
class WriteError : public core::Error {
public:
    WriteError(const std::filesystem::path& file, const std::string& problem)
        : core::Error(file.string() + ": " + problem) {}
};

}  // namespace lidarloop::io

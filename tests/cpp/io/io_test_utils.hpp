#pragma once

// Test helpers for the io module: checking the errors the readers throw.

#include <filesystem>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "lidarloop/io/read_error.hpp"
#include "test_utils.hpp"

namespace lidarloop::test {

/// The io::ReadError that `read()` throws; nullopt when it returns. Any other exception escapes
/// and fails the test.
template <typename Read>
std::optional<io::ReadError> CatchReadError(Read&& read) {
    try {
        read();
    } catch (const io::ReadError& e) {
        return e;
    }
    return std::nullopt;
}

/// The message of the io::ReadError that `read()` throws; "no ReadError" when it returns.
template <typename Read>
std::string ReadErrorOf(Read&& read) {
    const auto error = CatchReadError(read);
    return error ? error->what() : "no ReadError";
}

/// Expects `read(file)` (e.g. `read` = io::ReadPcd) to throw an io::ReadError for `file` whose
/// message names the file and contains `phrase`.
template <typename Read>
void ExpectReadError(Read&& read, const std::filesystem::path& file, const std::string& phrase) {
    const auto error = CatchReadError([&] { read(file); });
    if (!error) {
        ADD_FAILURE() << "no ReadError for " << file;
        return;
    }
    const std::string message = error->what();
    EXPECT_NE(message.find(phrase), std::string::npos) << message;
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_EQ(error->file(), file);
}

}  // namespace lidarloop::test

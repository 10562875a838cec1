#pragma once

// Test helpers for the io module: checking the errors the readers throw, and the fixtures the
// scan format tests share.

#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "lidarloop/core/point_cloud.hpp"
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

/// A scan reader: io::ReadPcd, io::ReadPly, ...
using ScanReader = std::function<core::PointCloud(const std::filesystem::path&)>;

/// One encoding of a scan format, as a writer and the reader that must give the cloud back.
struct ScanFormat {
    std::string name;       ///< Names the test instances: letters and digits only.
    std::string extension;  ///< With the dot: ".pcd".
    std::function<void(const std::filesystem::path&, const core::PointCloud&)> write;
    ScanReader read;
};

/// gtest shows a failing instance's parameter by its name.
inline void PrintTo(const ScanFormat& format, std::ostream* os) { *os << format.name; }

/// For INSTANTIATE_TEST_SUITE_P: the instance is named after its format.
inline std::string ScanFormatName(const ::testing::TestParamInfo<ScanFormat>& info) {
    return info.param.name;
}

/// Round trips through a file in a temporary folder. The cases, written once for every format,
/// are in test_scan_round_trip.cpp; each format's test file instantiates them with its encodings:
///   INSTANTIATE_TEST_SUITE_P(Pcd, ScanRoundTrip, ::testing::Values(...), ScanFormatName);
class ScanRoundTrip : public ::testing::TestWithParam<ScanFormat> {
protected:
    /// Writes `cloud` with the format's writer and reads it back with its reader.
    core::PointCloud RoundTrip(const core::PointCloud& cloud) {
        const std::filesystem::path file = dir_ / ("cloud" + GetParam().extension);
        GetParam().write(file, cloud);
        return GetParam().read(file);
    }
    TempDir dir_;
};

/// Fixture of a scan reader's bad-input tests: files written into a temporary folder and the
/// ReadError the reader throws for them.
class ScanReaderErrors : public ::testing::Test {
protected:
    /// `read` reads files whose names end in `extension` (with the dot: ".pcd").
    ScanReaderErrors(ScanReader read, std::string extension)
        : read_(std::move(read)), extension_(std::move(extension)) {}

    /// Writes `contents` verbatim to bad<extension> in the folder and returns its path.
    std::filesystem::path Write(const std::string& contents) const {
        const std::filesystem::path file = dir_ / ("bad" + extension_);
        WriteFile(file, contents);
        return file;
    }

    /// Expects reading `file` to throw a ReadError that names the file and contains `phrase`.
    void ExpectReadError(const std::filesystem::path& file, const std::string& phrase) const {
        test::ExpectReadError(read_, file, phrase);
    }

    TempDir dir_;

private:
    ScanReader read_;
    std::string extension_;
};

}  // namespace lidarloop::test

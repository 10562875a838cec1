#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <string>
#include <string_view>

#include <gtest/gtest.h>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::test {

/// A fresh temporary folder per test, removed at the end of the test.
class TempDir {
public:
    TempDir() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string name = "lidarloop_test";
        if (info != nullptr)
            name += std::string("_") + info->test_suite_name() + "_" + info->name();
        for (char& c : name) {
            if (c == '/') c = '_';
        }
        path_ = std::filesystem::temp_directory_path() / name;
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ignored;
        std::filesystem::remove_all(path_, ignored);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    std::filesystem::path operator/(const std::string& file) const { return path_ / file; }
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

/// Writes `bytes` verbatim to `file`.
inline void WriteFile(const std::filesystem::path& file, const std::string& bytes) {
    std::ofstream out(file, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

/// Reads a whole file into a string.
inline std::string ReadFile(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// `count` points uniform in a cube of half-side `half_side_m`, seeded.
inline core::PointCloud RandomCloud(std::size_t count, unsigned seed, float half_side_m = 20.0f) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> coordinate(-half_side_m, half_side_m);
    core::PointCloud cloud(count);
    for (auto& p : cloud) p = {coordinate(rng), coordinate(rng), coordinate(rng)};
    return cloud;
}

/// Path of a fixture under tests/data.
inline std::filesystem::path DataFile(const std::string& name) {
    return std::filesystem::path(LIDARLOOP_TEST_DATA_DIR) / name;
}

/// Replaces the first `from` in `text` by `to`; fails the test when `text` has no `from`.
inline void ReplaceOnce(std::string& text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
}

/// Exact equality per coordinate: bit patterns for numbers (so -0 differs from +0), any NaN for
/// NaN.
inline void ExpectSameCloud(const core::PointCloud& actual, const core::PointCloud& expected) {
    ASSERT_EQ(actual.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
        for (int axis = 0; axis < 3; ++axis) {
            const float a = actual[i][axis];
            const float e = expected[i][axis];
            const bool same =
                std::isnan(e) ? std::isnan(a)
                              : std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(e);
            EXPECT_TRUE(same) << "point " << i << " axis " << axis << ": read " << a
                              << ", expected " << e;
        }
    }
}

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

/// Success when `message` contains `phrase`; the failure shows both.
inline ::testing::AssertionResult Contains(const std::string& message, std::string_view phrase) {
    if (message.find(phrase) != std::string::npos) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "'" << phrase << "' not in: " << message;
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

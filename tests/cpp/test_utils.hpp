#pragma once

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::test {

// Constants that many tests spell out: declared once, so that test files can share a unity batch.
inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr float kInfFloat = std::numeric_limits<float>::infinity();
inline constexpr float kNanFloat = std::numeric_limits<float>::quiet_NaN();
inline constexpr double kDeg = std::numbers::pi / 180.0;  // radians per degree

/// Skips the test in a build with AddressSanitizer (scripts/test's first pass, the dev preset): for
/// run-scale tests that register hundreds of scan pairs, a minute or more there and seconds in the
/// release suite, which runs them. Lighter tests cover the same code under the sanitizers.
/// kSanitizedBuild says which build this is, for a run-scale test that runs smaller there.
/// GCC says ASan with __SANITIZE_ADDRESS__, clang (the dev preset's compiler) with __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define LIDARLOOP_TEST_ADDRESS_SANITIZER
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LIDARLOOP_TEST_ADDRESS_SANITIZER
#endif
#endif
#if defined(LIDARLOOP_TEST_ADDRESS_SANITIZER)
#define LIDARLOOP_RELEASE_SUITE_ONLY() \
    GTEST_SKIP() << "run-scale: the release suite runs it (minutes under the sanitizers)"
inline constexpr bool kSanitizedBuild = true;
#else
#define LIDARLOOP_RELEASE_SUITE_ONLY() static_cast<void>(0)
inline constexpr bool kSanitizedBuild = false;
#endif

/// A fresh temporary folder per test, removed at the end of the test. Named after the test, the
/// process and a count, so that the same test running in two build trees at once, or two
/// folders of one test, never share a folder.
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
        static std::atomic<int> count{0};
        name += "_" + std::to_string(::getpid()) + "_" + std::to_string(count++);
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

/// A uniformly random rotation (a normalised quaternion of four normal draws) from the test's own
/// generator: Eigen's UnitRandom draws from the global std::rand, which makes one test's draws
/// depend on which tests ran before it.
inline Eigen::Matrix3d RandomRotation(std::mt19937& rng) {
    std::normal_distribution<double> normal(0.0, 1.0);
    return Eigen::Quaterniond{normal(rng), normal(rng), normal(rng), normal(rng)}
        .normalized()
        .toRotationMatrix();
}

/// `cloud` with every point p moved to R p + t.
inline core::PointCloud Transformed(const core::PointCloud& cloud, const Eigen::Matrix3f& R,
                                    const Eigen::Vector3f& t = Eigen::Vector3f::Zero()) {
    core::PointCloud out = cloud;
    for (auto& p : out) p = R * p + t;
    return out;
}

/// Path of a fixture under tests/data.
/// The path between scans i and j (metres), walked step by step over `poses`: the brute-force
/// reference for core::CumulativePathM and the gaps and columns built on it.
inline double BrutePathM(const std::vector<core::StampedPose>& poses, std::size_t i,
                         std::size_t j) {
    double path_m = 0.0;
    for (std::size_t k = std::min(i, j); k < std::max(i, j); ++k) {
        path_m +=
            (poses[k + 1].T_world_sensor.translation() - poses[k].T_world_sensor.translation())
                .norm();
    }
    return path_m;
}

inline std::filesystem::path DataFile(const std::string& name) {
    return std::filesystem::path(LIDARLOOP_TEST_DATA_DIR) / name;
}

/// Success when `message` contains `phrase`; the failure shows both.
inline ::testing::AssertionResult Contains(const std::string& message, std::string_view phrase) {
    if (message.find(phrase) != std::string::npos) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "'" << phrase << "' not in: " << message;
}

/// The message of the core::ConfigError that `call()` throws; "no ConfigError" when it returns.
/// Any other exception escapes and fails the test.
template <typename Call>
std::string ConfigErrorOf(Call&& call) {
    try {
        call();
    } catch (const core::ConfigError& e) {
        return e.what();
    }
    return "no ConfigError";
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

}  // namespace lidarloop::test

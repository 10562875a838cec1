// Error messages quote input text through core::Quoted: one huge token (a 50 MB line without a
// separator, issue 25) must give a short message in every reader, not a copy of the token.
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "io/io_test_utils.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/osnabrueck.hpp"
#include "lidarloop/io/pcd.hpp"
#include "lidarloop/io/ply.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/io/results_csv.hpp"
#include "lidarloop/io/xyz.hpp"

namespace lidarloop::io {
namespace {

using test::Contains;
using test::ReadErrorOf;

constexpr std::size_t kHugeChars = 1'000'000;
constexpr std::size_t kMaxMessageChars = 300;

const std::string& HugeToken() {
    static const std::string token(kHugeChars, '7');
    return token;
}

TEST(Quoted, KeepsShortTokens) {
    EXPECT_EQ(core::Quoted("abc"), "'abc'");
    EXPECT_EQ(core::Quoted(""), "''");
    EXPECT_EQ(core::Quoted(std::string(40, 'x')), "'" + std::string(40, 'x') + "'");
}

TEST(Quoted, CutsLongTokensAndSaysHowLong) {
    EXPECT_EQ(core::Quoted(std::string(41, 'x')),
              "'" + std::string(40, 'x') + "...' (41 characters)");
    const std::string quoted = core::Quoted(HugeToken());
    EXPECT_LT(quoted.size(), 70u) << quoted;
    EXPECT_TRUE(Contains(quoted, "(1000000 characters)"));
}

TEST(Quoted, EscapesControlCharactersAndCutsBetweenUtf8Characters) {
    EXPECT_EQ(core::Quoted("a\nb\x7f"), "'a\\x0ab\\x7f'");
    // 39 ASCII bytes, then a two-byte character across the 40-byte cut: it is left out whole.
    const std::string token = std::string(39, 'x') + "\xc3\xa9" + "tail";
    EXPECT_EQ(core::Quoted(token), "'" + std::string(39, 'x') + "...' (45 characters)");
}

// Writes `text` to `name` and reads it with `read`; the message names the file and stays short.
void ExpectShortError(const std::string& name, const std::string& text,
                      const std::function<void(const std::filesystem::path&)>& read,
                      const std::string& phrase) {
    test::TempDir dir;
    test::WriteFile(dir / name, text);
    const std::string message = ReadErrorOf([&] { read(dir / name); });
    EXPECT_LT(message.size(), kMaxMessageChars) << message.substr(0, 2 * kMaxMessageChars);
    EXPECT_TRUE(Contains(message, phrase));
    EXPECT_TRUE(Contains(message, " characters)"));
}

TEST(LongTokens, XyzPosesAndOsnabrueckCutTheToken) {
    const std::string token = "x" + HugeToken();
    ExpectShortError("a.xyz", "1 2 " + token + "\n", ReadXyz, "line 1: 'x777");
    ExpectShortError("poses.txt", token + " 0 0 0 0 0 0 1\n", ReadTumPoses, "is not a number");
    ExpectShortError("a.pose", "0 0 " + token + "\n0 0 0\n", ReadOsnabrueckPose, "is not a number");
}

TEST(LongTokens, PcdAndPlyHeadersCutTheToken) {
    const std::string token = "x" + HugeToken();
    ExpectShortError("a.pcd", "VERSION 0.7\n" + token + " 1\n", ReadPcd, "unknown header keyword");
    ExpectShortError("b.pcd",
                     "VERSION 0.7\nFIELDS " + token +
                         " y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                         "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n",
                     ReadPcd, "no 'x' field");
    ExpectShortError("a.ply", "ply\nformat ascii 1.0\nelement vertex " + token + "\n", ReadPly,
                     "element count");
    ExpectShortError("b.ply",
                     "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float "
                     "y\nproperty float z\nend_header\n1 2 " +
                         token + "\n",
                     ReadPly, "is not a number");
}

TEST(LongTokens, ResultsCsvCutsTheToken) {
    ExpectShortError("results.csv", "query,match,distance\n1,0," + HugeToken() + "x\n",
                     ReadResultsCsv, "distance '777");
    ExpectShortError("results.csv", "query,match,distance\n" + HugeToken() + "x,0,1\n",
                     ReadResultsCsv, "is not a scan number");
}

TEST(LongTokens, ConfigYamlCutsKeysAndValues) {
    const auto expect_short = [](const std::string& yaml, const std::string& phrase) {
        RunConfig config;
        const std::string message = ReadErrorOf([&] { ApplyConfigYaml(yaml, "my.yaml", config); });
        EXPECT_LT(message.size(), kMaxMessageChars) << message.substr(0, 2 * kMaxMessageChars);
        EXPECT_TRUE(Contains(message, phrase)) << message.substr(0, 2 * kMaxMessageChars);
    };
    // An implicit key is at most 1024 characters in YAML; an explicit one ("? ") is unlimited.
    expect_short("histogram:\n  ? x" + HugeToken() + "\n  : 1\n", "unknown key");
    expect_short("? x" + HugeToken() + "\n: 1\n? x" + HugeToken() + "\n: 2\n", "appears twice");
    expect_short("histogram:\n  bins: x" + HugeToken() + "\n", "expected an integer");
    expect_short("method: x" + HugeToken() + "\n", "unknown method");
    expect_short("histogram:\n  out_of_range: x" + HugeToken() + "\n", "histogram.out_of_range");
    expect_short("histogram:\n  threshold: x" + HugeToken() + "\n", "moved to");
}

}  // namespace
}  // namespace lidarloop::io

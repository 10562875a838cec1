#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/io_test_utils.hpp"
#include "lidarloop/io/pcd.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {

// gtest prints an enum as its bytes ("4-byte object <01-00 00-00>") unless it finds a PrintTo by
// argument-dependent lookup, that is in the enum's namespace. The name also names the test.
void PrintTo(PcdEncoding encoding, std::ostream* os) {
    switch (encoding) {
        case PcdEncoding::kAscii:
            *os << "Ascii";
            return;
        case PcdEncoding::kBinary:
            *os << "Binary";
            return;
        case PcdEncoding::kBinaryCompressed:
            *os << "BinaryCompressed";
            return;
    }
    *os << "Unknown";
}

namespace {

using core::PointCloud;
using test::ExpectSameCloud;
using test::ReadFile;
using test::ReplaceOnce;
using test::ScanRoundTrip;
using test::TempDir;
using test::WriteFile;

static_assert(std::endian::native == std::endian::little, "the byte builders assume it");

template <typename T>
void Append(std::string& bytes, T value) {
    char buffer[sizeof(T)];
    std::memcpy(buffer, &value, sizeof(T));
    bytes.append(buffer, sizeof(T));
}

// The header of an x y z float cloud with `points` points; data starts on line 11.
std::string XyzHeader(std::size_t points, const std::string& data) {
    const std::string n = std::to_string(points);
    return "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + n +
           "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + n + "\nDATA " + data + "\n";
}

// A valid LZF stream made only of literal runs (at most 32 bytes each).
std::string LzfLiterals(const std::string& data) {
    std::string out;
    for (std::size_t at = 0; at < data.size(); at += 32) {
        const std::size_t run = std::min<std::size_t>(32, data.size() - at);
        out += static_cast<char>(run - 1);
        out += data.substr(at, run);
    }
    return out;
}

std::string CompressedBlock(const std::string& unpacked) {
    const std::string payload = LzfLiterals(unpacked);
    std::string block;
    Append(block, static_cast<std::uint32_t>(payload.size()));
    Append(block, static_cast<std::uint32_t>(unpacked.size()));
    return block + payload;
}

// ---------------------------------------------------------------------------------------------
// Round trips

// The cases are in test_scan_round_trip.cpp.
test::ScanFormat Pcd(PcdEncoding encoding) {
    return {::testing::PrintToString(encoding), ".pcd",
            [encoding](const std::filesystem::path& file, const PointCloud& cloud) {
                WritePcd(file, cloud, encoding);
            },
            ReadPcd};
}

INSTANTIATE_TEST_SUITE_P(Pcd, ScanRoundTrip,
                         ::testing::Values(Pcd(PcdEncoding::kAscii), Pcd(PcdEncoding::kBinary),
                                           Pcd(PcdEncoding::kBinaryCompressed)),
                         test::ScanFormatName);

// ---------------------------------------------------------------------------------------------
// Writer output

TEST(PcdWriter, WritesTheV07HeaderAndLittleEndianFloats) {
    TempDir dir;
    WritePcd(dir / "one.pcd", {{1.0f, -2.0f, 0.5f}}, PcdEncoding::kBinary);
    std::string expected = "# .PCD v0.7 - Point Cloud Data file format\n" + XyzHeader(1, "binary");
    Append(expected, 1.0f);
    Append(expected, -2.0f);
    Append(expected, 0.5f);
    EXPECT_EQ(ReadFile(dir / "one.pcd"), expected);
}

TEST(PcdWriter, AsciiUsesNineSignificantDigits) {
    TempDir dir;
    WritePcd(dir / "one.pcd", {{0.1f, 1.5f, test::kNanFloat}}, PcdEncoding::kAscii);
    const std::string text = ReadFile(dir / "one.pcd");
    EXPECT_NE(text.find("DATA ascii\n0.100000001 1.5 nan\n"), std::string::npos) << text;
}

TEST(PcdWriter, CompressedIsSmallerForRepetitiveData) {
    TempDir dir;
    const PointCloud cloud(5000, Eigen::Vector3f(1.0f, 2.0f, 3.0f));
    WritePcd(dir / "binary.pcd", cloud, PcdEncoding::kBinary);
    WritePcd(dir / "compressed.pcd", cloud, PcdEncoding::kBinaryCompressed);
    EXPECT_LT(ReadFile(dir / "compressed.pcd").size() * 20, ReadFile(dir / "binary.pcd").size());
    ExpectSameCloud(ReadPcd(dir / "compressed.pcd"), cloud);
}

// ---------------------------------------------------------------------------------------------
// Hand-written files with fields other than x y z

struct MixedPoint {
    double timestamp;
    float x;
    double y;
    float z;
    float intensity;
    std::uint16_t ring;
    std::uint16_t descriptor[3];
};

const std::vector<MixedPoint> kMixedPoints = {
    {1.0e9, 1.5f, -2.25, 3.0f, 0.5f, 7, {1, 2, 3}},
    {1.0e9 + 0.1, -0.125f, 0.1, 42.0f, 12.0f, 63, {65535, 0, 9}},
    {1.0e9 + 0.2, 100.0f, 1.0e-3, -7.75f, 99.0f, 0, {4, 5, 6}},
};

// timestamp before x, y as double, a padding field "_" and a COUNT 3 field after z.
const std::string kMixedHeader =
    "# .PCD v0.7 - Point Cloud Data file format\n"
    "VERSION .7\n"
    "FIELDS timestamp x y z intensity ring _ descriptor\n"
    "SIZE 8 4 8 4 4 2 1 2\n"
    "TYPE F F F F F U U U\n"
    "COUNT 1 1 1 1 1 1 3 3\n"
    "WIDTH 3\n"
    "HEIGHT 1\n"
    "VIEWPOINT 0 0 0 1 0 0 0\n"
    "POINTS 3\n";

PointCloud MixedExpected() {
    PointCloud cloud;
    for (const auto& p : kMixedPoints) cloud.emplace_back(p.x, static_cast<float>(p.y), p.z);
    return cloud;
}

std::string MixedAscii() {
    std::string text = kMixedHeader + "DATA ascii\n";
    for (const auto& p : kMixedPoints) {
        text += std::to_string(p.timestamp) + " " + std::to_string(p.x) + " " +
                std::to_string(p.y) + " " + std::to_string(p.z) + " " +
                std::to_string(p.intensity) + " " + std::to_string(p.ring) + " 0 0 0";
        for (const auto d : p.descriptor) text += " " + std::to_string(d);
        text += "\n";
    }
    return text;
}

std::string MixedBinary() {
    std::string bytes = kMixedHeader + "DATA binary\n";
    for (const auto& p : kMixedPoints) {
        Append(bytes, p.timestamp);
        Append(bytes, p.x);
        Append(bytes, p.y);
        Append(bytes, p.z);
        Append(bytes, p.intensity);
        Append(bytes, p.ring);
        bytes += std::string(3, '\xAA');  // padding
        for (const auto d : p.descriptor) Append(bytes, d);
    }
    return bytes;
}

// Field-major, without the padding field, as PCL writes it.
std::string MixedCompressed() {
    std::string unpacked;
    for (const auto& p : kMixedPoints) Append(unpacked, p.timestamp);
    for (const auto& p : kMixedPoints) Append(unpacked, p.x);
    for (const auto& p : kMixedPoints) Append(unpacked, p.y);
    for (const auto& p : kMixedPoints) Append(unpacked, p.z);
    for (const auto& p : kMixedPoints) Append(unpacked, p.intensity);
    for (const auto& p : kMixedPoints) Append(unpacked, p.ring);
    for (const auto& p : kMixedPoints) {
        for (const auto d : p.descriptor) Append(unpacked, d);
    }
    return kMixedHeader + "DATA binary_compressed\n" + CompressedBlock(unpacked);
}

TEST(PcdRead, MixedFieldsAscii) {
    TempDir dir;
    WriteFile(dir / "mixed.pcd", MixedAscii());
    ExpectSameCloud(ReadPcd(dir / "mixed.pcd"), MixedExpected());
}

TEST(PcdRead, MixedFieldsBinary) {
    TempDir dir;
    WriteFile(dir / "mixed.pcd", MixedBinary());
    ExpectSameCloud(ReadPcd(dir / "mixed.pcd"), MixedExpected());
}

TEST(PcdRead, MixedFieldsBinaryCompressed) {
    TempDir dir;
    WriteFile(dir / "mixed.pcd", MixedCompressed());
    ExpectSameCloud(ReadPcd(dir / "mixed.pcd"), MixedExpected());
}

TEST(PcdRead, CrlfHeaderWithoutVersionAndCount) {
    TempDir dir;
    std::string bytes =
        "# comment\r\nFIELDS z y x\r\nSIZE 4 4 4\r\nTYPE F F F\r\nWIDTH 2\r\nHEIGHT 1\r\n"
        "POINTS 2\r\nDATA binary\r\n";
    for (const float value : {3.0f, 2.0f, 1.0f, -6.0f, -5.0f, -4.0f}) Append(bytes, value);
    WriteFile(dir / "crlf.pcd", bytes);
    ExpectSameCloud(ReadPcd(dir / "crlf.pcd"), {{1.0f, 2.0f, 3.0f}, {-4.0f, -5.0f, -6.0f}});
}

TEST(PcdRead, OrganisedCloudKeepsNanPoints) {
    TempDir dir;
    std::string text = XyzHeader(4, "ascii");
    ReplaceOnce(text, "WIDTH 4\nHEIGHT 1", "WIDTH 2\nHEIGHT 2");
    text += "1 2 3\nnan nan nan\n4 5 6\nNaN NaN NaN\n";
    WriteFile(dir / "organised.pcd", text);
    ExpectSameCloud(ReadPcd(dir / "organised.pcd"),
                    {{1, 2, 3},
                     {test::kNanFloat, test::kNanFloat, test::kNanFloat},
                     {4, 5, 6},
                     {test::kNanFloat, test::kNanFloat, test::kNanFloat}});
}

// ---------------------------------------------------------------------------------------------
// Bad input

class PcdErrors : public test::ScanReaderErrors {
protected:
    PcdErrors() : ScanReaderErrors(ReadPcd, ".pcd") {}
    // A valid file of `points` random points, returned as bytes, and its header length.
    std::string Valid(std::size_t points, PcdEncoding encoding, std::size_t* header_size) {
        WritePcd(dir_ / "valid.pcd", test::RandomCloud(points, 3), encoding);
        const std::string bytes = ReadFile(dir_ / "valid.pcd");
        const std::string data_line =
            encoding == PcdEncoding::kBinary ? "DATA binary\n" : "DATA binary_compressed\n";
        *header_size = bytes.find(data_line) + data_line.size();
        return bytes;
    }
};

TEST_F(PcdErrors, MissingFile) { ExpectReadError(dir_ / "absent.pcd", "no such file"); }

TEST_F(PcdErrors, NotAPcdFile) {
    ExpectReadError(Write("ply\nformat ascii 1.0\n"), "line 1: unknown header keyword 'ply'");
}

TEST_F(PcdErrors, MissingDataLine) {
    std::string text = XyzHeader(1, "ascii");
    ReplaceOnce(text, "DATA ascii\n", "");
    ExpectReadError(Write(text), "header has no DATA line");
}

TEST_F(PcdErrors, UnknownDataType) {
    ExpectReadError(Write(XyzHeader(1, "binary_lzma")),
                    "line 10: unknown DATA type 'binary_lzma' (expected ascii, binary or "
                    "binary_compressed)");
}

TEST_F(PcdErrors, UnsupportedVersion) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3\n";
    ReplaceOnce(text, "VERSION 0.7", "VERSION 0.8");
    ExpectReadError(Write(text), "line 1: unsupported VERSION");
}

TEST_F(PcdErrors, MissingXField) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3\n";
    ReplaceOnce(text, "FIELDS x y z", "FIELDS a y z");
    ExpectReadError(Write(text), "no 'x' field (FIELDS: 'a' 'y' 'z')");
}

TEST_F(PcdErrors, XFieldNamedTwice) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3\n";
    ReplaceOnce(text, "FIELDS x y z", "FIELDS x y x");
    ExpectReadError(Write(text), "field 'x' is named twice (FIELDS: 'x' 'y' 'x')");
}

TEST_F(PcdErrors, UnsignedXField) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3\n";
    ReplaceOnce(text, "TYPE F F F", "TYPE U F F");
    ExpectReadError(Write(text), "field 'x' has TYPE U SIZE 4");
}

TEST_F(PcdErrors, HalfFloatZField) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3\n";
    ReplaceOnce(text, "SIZE 4 4 4", "SIZE 4 4 2");
    ExpectReadError(Write(text), "field 'z' has TYPE F SIZE 2");
}

TEST_F(PcdErrors, XWithCountThree) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3 4 5\n";
    ReplaceOnce(text, "COUNT 1 1 1", "COUNT 3 1 1");
    ExpectReadError(Write(text), "field 'x' has COUNT 3");
}

TEST_F(PcdErrors, FieldSizeNotAPowerOfTwo) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3 4\n";
    ReplaceOnce(text, "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1",
                "FIELDS x y z rgb\nSIZE 4 4 4 3\nTYPE F F F U\nCOUNT 1 1 1 1");
    ExpectReadError(Write(text), "field 'rgb' has SIZE 3");
}

TEST_F(PcdErrors, SizeListShorterThanFields) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3\n";
    ReplaceOnce(text, "SIZE 4 4 4", "SIZE 4 4");
    ExpectReadError(Write(text), "SIZE has 2 entries but FIELDS has 3");
}

TEST_F(PcdErrors, CountListLongerThanFields) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3\n";
    ReplaceOnce(text, "COUNT 1 1 1", "COUNT 1 1 1 1");
    ExpectReadError(Write(text), "COUNT has 4 entries but FIELDS has 3");
}

TEST_F(PcdErrors, MissingTypeLine) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3\n";
    ReplaceOnce(text, "TYPE F F F\n", "");
    ExpectReadError(Write(text), "header has no TYPE line");
}

TEST_F(PcdErrors, UnknownTypeLetter) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3\n";
    ReplaceOnce(text, "TYPE F F F", "TYPE F F D");
    ExpectReadError(Write(text), "line 4: TYPE 'D' is not I, U or F");
}

TEST_F(PcdErrors, MissingPoints) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3\n";
    ReplaceOnce(text, "POINTS 1\n", "");
    ExpectReadError(Write(text), "header has no POINTS line");
}

TEST_F(PcdErrors, PointsDisagreeWithWidthTimesHeight) {
    std::string text = XyzHeader(5, "ascii") + "1 2 3\n1 2 3\n1 2 3\n1 2 3\n1 2 3\n";
    ReplaceOnce(text, "WIDTH 5\nHEIGHT 1", "WIDTH 2\nHEIGHT 2");
    ExpectReadError(Write(text), "POINTS 5 does not equal WIDTH*HEIGHT = 2*2");
}

TEST_F(PcdErrors, NonIntegerWidth) {
    std::string text = XyzHeader(1, "ascii") + "1 2 3\n";
    ReplaceOnce(text, "WIDTH 1", "WIDTH -1");
    ExpectReadError(Write(text), "line 6: WIDTH value '-1' is not a non-negative integer");
}

TEST_F(PcdErrors, TruncatedBinary) {
    std::size_t header_size = 0;
    const std::string bytes = Valid(100, PcdEncoding::kBinary, &header_size);
    ASSERT_EQ(bytes.size(), header_size + 1200);
    ExpectReadError(Write(bytes.substr(0, header_size + 600)),
                    "data truncated: POINTS 100 of 12 bytes need 1200 bytes, but 600 follow");
}

// As the ASCII reader refuses more lines than POINTS: a wrong count, so maybe the wrong points.
TEST_F(PcdErrors, MoreBinaryDataThanPoints) {
    std::size_t header_size = 0;
    const std::string bytes = Valid(100, PcdEncoding::kBinary, &header_size);
    ExpectReadError(Write(bytes + std::string(12, '\0')),
                    "12 bytes follow the 100 points of POINTS: the header's count is wrong");
}

TEST_F(PcdErrors, TruncatedCompressed) {
    std::size_t header_size = 0;
    const std::string bytes = Valid(1000, PcdEncoding::kBinaryCompressed, &header_size);
    ExpectReadError(Write(bytes.substr(0, header_size + (bytes.size() - header_size) / 2)),
                    "data truncated: the compressed block has");
    ExpectReadError(Write(bytes.substr(0, header_size + 5)), "needs an 8-byte size header");
}

TEST_F(PcdErrors, TruncatedAscii) {
    ExpectReadError(Write(XyzHeader(3, "ascii") + "1 2 3\n4 5 6\n"),
                    "data truncated: POINTS is 3 but the file has 2 data lines");
}

TEST_F(PcdErrors, MoreAsciiLinesThanPoints) {
    ExpectReadError(Write(XyzHeader(1, "ascii") + "1 2 3\n4 5 6\n"),
                    "line 12: more data lines than POINTS 1");
}

TEST_F(PcdErrors, CorruptLzfPayload) {
    std::size_t header_size = 0;
    std::string bytes = Valid(1000, PcdEncoding::kBinaryCompressed, &header_size);
    // The block starts with a literal run (control byte < 32); flipped, it becomes a back
    // reference to before the start of the output, which a valid stream never holds.
    ASSERT_LT(static_cast<unsigned char>(bytes[header_size + 8]), 32);
    for (std::size_t i = header_size + 8; i < header_size + 12; ++i) bytes[i] ^= '\xFF';
    ExpectReadError(Write(bytes), "corrupt LZF block: invalid compressed data");
}

TEST_F(PcdErrors, UncompressedSizeDisagreesWithPoints) {
    std::size_t header_size = 0;
    std::string bytes = Valid(1000, PcdEncoding::kBinaryCompressed, &header_size);
    const std::uint32_t lie = 12012;
    std::memcpy(bytes.data() + header_size + 4, &lie, 4);
    ExpectReadError(Write(bytes),
                    "uncompressed size 12012 of the binary_compressed block does not match "
                    "POINTS x record size = 12000");
}

TEST_F(PcdErrors, BlockDecompressesToLessThanStated) {
    std::size_t header_size = 0;
    std::string bytes = Valid(1000, PcdEncoding::kBinaryCompressed, &header_size);
    ReplaceOnce(bytes, "WIDTH 1000", "WIDTH 1001");
    ReplaceOnce(bytes, "POINTS 1000", "POINTS 1001");
    const std::uint32_t lie = 12012;
    std::memcpy(bytes.data() + header_size + 4, &lie, 4);
    ExpectReadError(Write(bytes),
                    "corrupt LZF block: it decompresses to 12000 bytes, but its header states "
                    "12012");
}

TEST_F(PcdErrors, BlockDecompressesToMoreThanStated) {
    std::string unpacked;
    for (int i = 0; i < 9; ++i) Append(unpacked, static_cast<float>(i));
    std::string block = CompressedBlock(unpacked);
    const std::uint32_t lie = 24;  // two points instead of the three in the block
    std::memcpy(block.data() + 4, &lie, 4);
    ExpectReadError(Write(XyzHeader(2, "binary_compressed") + block),
                    "corrupt LZF block: it decompresses to more than the 24 bytes stated");
}

TEST_F(PcdErrors, UncompressedSizeBeyondWhatLzfCanProduce) {
    std::string block;
    Append(block, std::uint32_t{4});
    Append(block, std::uint32_t{1200000});
    block += std::string(
        "\x02"
        "abc",
        4);
    ExpectReadError(Write(XyzHeader(100000, "binary_compressed") + block),
                    "corrupt LZF block: 4 compressed bytes cannot expand to 1200000");
}

TEST_F(PcdErrors, AbsurdPointsAreRejectedBeforeAllocating) {
    const std::size_t absurd = 1'000'000'000'000'000;
    const std::string data = "1 2 3\n4 5 6\n7 8 9\n";
    ExpectReadError(Write(XyzHeader(absurd, "binary") + data),
                    "POINTS 1000000000000000 of 12 bytes need 12000000000000000 bytes, but 18 "
                    "follow the header");
    ExpectReadError(Write(XyzHeader(absurd, "binary_compressed") + data),
                    "exceed the 4 GiB limit of a binary_compressed block");
    ExpectReadError(Write(XyzHeader(absurd, "ascii") + data),
                    "POINTS is 1000000000000000 but the file has 3 data lines");
    // POINTS times the record size overflows 64 bits.
    ExpectReadError(Write(XyzHeader(10'000'000'000'000'000'000u, "binary") + data),
                    "need more than 18446744073709551615 bytes");
}

TEST_F(PcdErrors, AbsurdCountIsRejectedBeforeAllocating) {
    for (const std::string data : {"ascii", "binary", "binary_compressed"}) {
        std::string text = XyzHeader(1, data) + "1 2 3 4\n";
        ReplaceOnce(text, "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1",
                    "FIELDS x y z h\nSIZE 4 4 4 8\nTYPE F F F F\nCOUNT 1 1 1 4000000000000000000");
        ExpectReadError(Write(text),
                        "field 'h' with COUNT 4000000000000000000 makes one point "
                        "larger than the");
    }
}

TEST_F(PcdErrors, AsciiLineWithAMissingValue) {
    ExpectReadError(Write(XyzHeader(2, "ascii") + "1 2 3\n4 5\n"),
                    "line 12: expected at least 3 numbers, got 2");
}

TEST_F(PcdErrors, AsciiLineWithAnExtraValue) {
    ExpectReadError(Write(XyzHeader(2, "ascii") + "1 2 3\n4 5 6 7\n"),
                    "line 12: expected 3 values, got 4");
}

TEST_F(PcdErrors, AsciiNonNumber) {
    ExpectReadError(Write(XyzHeader(2, "ascii") + "1 2 3\n4 five 6\n"),
                    "line 12: 'five' is not a number");
}

}  // namespace
}  // namespace lidarloop::io

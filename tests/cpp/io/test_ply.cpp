#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <ostream>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include "io/io_test_utils.hpp"
#include "lidarloop/io/ply.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {

// gtest prints an enum as its bytes ("4-byte object <01-00 00-00>") unless it finds a PrintTo by
// argument-dependent lookup, that is in the enum's namespace. The names also name the tests.
void PrintTo(PlyEncoding encoding, std::ostream* os) {
    *os << (encoding == PlyEncoding::kAscii                ? "Ascii"
            : encoding == PlyEncoding::kBinaryLittleEndian ? "LittleEndian"
                                                           : "BigEndian");
}

void PrintTo(PlyScalar scalar, std::ostream* os) {
    *os << (scalar == PlyScalar::kFloat32 ? "Float32" : "Float64");
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

std::string FormatLine(PlyEncoding encoding) {
    switch (encoding) {
        case PlyEncoding::kAscii:
            return "format ascii 1.0\n";
        case PlyEncoding::kBinaryLittleEndian:
            return "format binary_little_endian 1.0\n";
        case PlyEncoding::kBinaryBigEndian:
            return "format binary_big_endian 1.0\n";
    }
    return "";
}

// The body of a PLY file, written value by value in one of the three encodings.
class Body {
public:
    explicit Body(PlyEncoding encoding) : encoding_(encoding) {}

    template <typename T>
    Body& Add(T value) {
        if (encoding_ == PlyEncoding::kAscii) {
            std::ostringstream text;
            text.precision(17);
            if constexpr (std::is_integral_v<T>) {
                text << static_cast<long long>(value);
            } else {
                text << value;
            }
            if (!row_start_) bytes_ += ' ';
            bytes_ += text.str();
            row_start_ = false;
            return *this;
        }
        char buffer[sizeof(T)];
        std::memcpy(buffer, &value, sizeof(T));
        if (encoding_ == PlyEncoding::kBinaryBigEndian) std::reverse(buffer, buffer + sizeof(T));
        bytes_.append(buffer, sizeof(T));
        return *this;
    }

    Body& EndRow() {
        if (encoding_ == PlyEncoding::kAscii) bytes_ += '\n';
        row_start_ = true;
        return *this;
    }

    const std::string& bytes() const { return bytes_; }

private:
    PlyEncoding encoding_;
    std::string bytes_;
    bool row_start_ = true;
};

// A vertex element of `count` float32 x y z vertices.
std::string XyzElement(std::size_t count) {
    return "element vertex " + std::to_string(count) +
           "\nproperty float x\nproperty float y\nproperty float z\n";
}

// The header of a float32 x y z cloud; ascii data starts on line 8.
std::string XyzHeader(PlyEncoding encoding, std::size_t count) {
    return "ply\n" + FormatLine(encoding) + XyzElement(count) + "end_header\n";
}

// ---------------------------------------------------------------------------------------------
// Round trips

// The cases are in test_scan_round_trip.cpp.
test::ScanFormat Ply(PlyEncoding encoding, PlyScalar scalar) {
    return {::testing::PrintToString(encoding) + ::testing::PrintToString(scalar), ".ply",
            [encoding, scalar](const std::filesystem::path& file, const PointCloud& cloud) {
                WritePly(file, cloud, encoding, scalar);
            },
            ReadPly};
}

INSTANTIATE_TEST_SUITE_P(
    Ply, ScanRoundTrip,
    ::testing::Values(Ply(PlyEncoding::kAscii, PlyScalar::kFloat32),
                      Ply(PlyEncoding::kAscii, PlyScalar::kFloat64),
                      Ply(PlyEncoding::kBinaryLittleEndian, PlyScalar::kFloat32),
                      Ply(PlyEncoding::kBinaryLittleEndian, PlyScalar::kFloat64),
                      Ply(PlyEncoding::kBinaryBigEndian, PlyScalar::kFloat32),
                      Ply(PlyEncoding::kBinaryBigEndian, PlyScalar::kFloat64)),
    test::ScanFormatName);

// ---------------------------------------------------------------------------------------------
// Writer output: a round trip alone cannot see a byte order swapped both ways.

const std::string kWrittenHeader =
    "ply\n"
    "format binary_big_endian 1.0\n"
    "comment written by lidarloop\n"
    "element vertex 1\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "end_header\n";

TEST(PlyWriter, BigEndianFloat32Bytes) {
    TempDir dir;
    WritePly(dir / "one.ply", {{1.0f, -2.0f, 0.5f}}, PlyEncoding::kBinaryBigEndian,
             PlyScalar::kFloat32);
    const std::string expected = kWrittenHeader + std::string("\x3F\x80\x00\x00", 4) +
                                 std::string("\xC0\x00\x00\x00", 4) +
                                 std::string("\x3F\x00\x00\x00", 4);
    EXPECT_EQ(ReadFile(dir / "one.ply"), expected);
}

TEST(PlyWriter, LittleEndianFloat64Bytes) {
    TempDir dir;
    WritePly(dir / "one.ply", {{1.0f, -2.0f, 0.5f}}, PlyEncoding::kBinaryLittleEndian,
             PlyScalar::kFloat64);
    std::string expected = kWrittenHeader;
    ReplaceOnce(expected, "binary_big_endian", "binary_little_endian");
    for (int i = 0; i < 3; ++i) ReplaceOnce(expected, "property float", "property double");
    expected += std::string("\x00\x00\x00\x00\x00\x00\xF0\x3F", 8) +
                std::string("\x00\x00\x00\x00\x00\x00\x00\xC0", 8) +
                std::string("\x00\x00\x00\x00\x00\x00\xE0\x3F", 8);
    EXPECT_EQ(ReadFile(dir / "one.ply"), expected);
}

TEST(PlyWriter, AsciiUsesMaxDigits10) {
    TempDir dir;
    WritePly(dir / "f.ply", {{0.1f, 1.5f, test::kNanFloat}}, PlyEncoding::kAscii,
             PlyScalar::kFloat32);
    WritePly(dir / "d.ply", {{0.1f, 1.5f, test::kNanFloat}}, PlyEncoding::kAscii,
             PlyScalar::kFloat64);
    EXPECT_NE(ReadFile(dir / "f.ply").find("end_header\n0.100000001 1.5 nan\n"), std::string::npos);
    EXPECT_NE(ReadFile(dir / "d.ply").find("end_header\n0.10000000149011612 1.5 nan\n"),
              std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// Hand-written files with other properties and elements

struct RichVertex {
    double x;
    float y;
    float z;
    std::uint8_t rgb[3];
    std::int16_t ring;
    std::vector<std::int16_t> extra;
};

const std::vector<RichVertex> kRichVertices = {
    {1.5, -2.25f, 3.0f, {255, 0, 10}, -3, {}},
    {0.1, 42.0f, -7.75f, {1, 2, 3}, 127, {5, -6, 7}},
    {-1.0e-3, 0.5f, 100.0f, {9, 8, 7}, 0, {-1}},
};

// A list element before the vertices, x as double, colours, a list inside the vertex, faces after.
std::string RichHeader(PlyEncoding encoding) {
    return "ply\n" + FormatLine(encoding) +
           "comment hand-written\n"
           "obj_info scanner test\n"
           "element sensor 2\n"
           "property uint8 id\n"
           "property list uchar int32 beams\n"
           "property float64 range\n"
           "element vertex 3\n"
           "property double x\n"
           "property float y\n"
           "property uchar red\n"
           "property uchar green\n"
           "property uchar blue\n"
           "property short ring\n"
           "property list ushort int16 extra\n"
           "property float32 z\n"
           "element face 2\n"
           "property list uchar int vertex_indices\n"
           "property char flag\n"
           "end_header\n";
}

std::string RichFile(PlyEncoding encoding) {
    Body body(encoding);
    body.Add(std::uint8_t{0}).Add(std::uint8_t{2}).Add(std::int32_t{16}).Add(std::int32_t{-1});
    body.Add(25.0).EndRow();
    body.Add(std::uint8_t{1}).Add(std::uint8_t{0}).Add(50.5).EndRow();
    for (const auto& v : kRichVertices) {
        body.Add(v.x).Add(v.y).Add(v.rgb[0]).Add(v.rgb[1]).Add(v.rgb[2]).Add(v.ring);
        body.Add(static_cast<std::uint16_t>(v.extra.size()));
        for (const auto e : v.extra) body.Add(e);
        body.Add(v.z).EndRow();
    }
    for (int f = 0; f < 2; ++f) {
        body.Add(std::uint8_t{3}).Add(0).Add(1).Add(2).Add(std::int8_t{-1}).EndRow();
    }
    return RichHeader(encoding) + body.bytes();
}

PointCloud RichExpected() {
    PointCloud cloud;
    for (const auto& v : kRichVertices) cloud.emplace_back(static_cast<float>(v.x), v.y, v.z);
    return cloud;
}

class PlyRead : public ::testing::TestWithParam<PlyEncoding> {};

TEST_P(PlyRead, SkipsOtherPropertiesAndElements) {
    TempDir dir;
    WriteFile(dir / "rich.ply", RichFile(GetParam()));
    ExpectSameCloud(ReadPly(dir / "rich.ply"), RichExpected());
}

TEST_P(PlyRead, DoublesBeyondTheFloatRangeRound) {
    TempDir dir;
    Body body(GetParam());
    const double above_max = 3.4028235e38;  // rounds to FLT_MAX, not to infinity
    body.Add(1e300).Add(-1e300).Add(above_max).EndRow();
    std::string text = XyzHeader(GetParam(), 1) + body.bytes();
    for (int i = 0; i < 3; ++i) ReplaceOnce(text, "property float ", "property double ");
    WriteFile(dir / "huge.ply", text);
    const float inf = std::numeric_limits<float>::infinity();
    ExpectSameCloud(ReadPly(dir / "huge.ply"), {{inf, -inf, std::numeric_limits<float>::max()}});
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, PlyRead,
                         ::testing::Values(PlyEncoding::kAscii, PlyEncoding::kBinaryLittleEndian,
                                           PlyEncoding::kBinaryBigEndian),
                         ::testing::PrintToStringParamName());

TEST(PlyReadHeader, AcceptsCrlfLinesAndSynonymTypes) {
    TempDir dir;
    Body body(PlyEncoding::kBinaryLittleEndian);
    body.Add(1.0f).Add(2.0f).Add(3.0f);
    WriteFile(dir / "crlf.ply",
              "ply\r\nformat binary_little_endian 1.0\r\nelement vertex 1\r\n"
              "property float32 z\r\nproperty float32 y\r\nproperty float32 x\r\nend_header\r\n" +
                  body.bytes());
    ExpectSameCloud(ReadPly(dir / "crlf.ply"), {{3.0f, 2.0f, 1.0f}});
}

// ---------------------------------------------------------------------------------------------
// Bad input

class PlyErrors : public test::ScanReaderErrors {
protected:
    PlyErrors() : ScanReaderErrors(ReadPly, ".ply") {}
};

TEST_F(PlyErrors, MissingFile) { ExpectReadError(dir_ / "absent.ply", "no such file"); }

TEST_F(PlyErrors, WrongMagic) {
    ExpectReadError(Write("PLY\nformat ascii 1.0\n"), "does not start with 'ply'");
    ExpectReadError(Write("VERSION 0.7\nFIELDS x y z\n"), "does not start with 'ply'");
    ExpectReadError(Write(""), "does not start with 'ply'");
}

TEST_F(PlyErrors, UnknownFormat) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 2 3\n";
    ReplaceOnce(text, "format ascii", "format binary_middle_endian");
    ExpectReadError(Write(text),
                    "line 2: unknown format 'binary_middle_endian' (expected ascii, "
                    "binary_little_endian or binary_big_endian)");
}

TEST_F(PlyErrors, UnsupportedVersion) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 2 3\n";
    ReplaceOnce(text, "ascii 1.0", "ascii 2.0");
    ExpectReadError(Write(text), "line 2: unsupported PLY version '2.0'");
}

TEST_F(PlyErrors, MissingFormatLine) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 2 3\n";
    ReplaceOnce(text, "format ascii 1.0\n", "");
    ExpectReadError(Write(text), "header has no format line");
}

TEST_F(PlyErrors, NoVertexElement) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 2 3\n";
    ReplaceOnce(text, "element vertex", "element point");
    ExpectReadError(Write(text), "header has no 'vertex' element");
}

TEST_F(PlyErrors, MissingXProperty) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 2 3\n";
    ReplaceOnce(text, "property float x", "property float intensity");
    ExpectReadError(Write(text), "element 'vertex' has no 'x' property");
}

TEST_F(PlyErrors, XPropertyNamedTwice) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 2 3\n";
    ReplaceOnce(text, "property float z", "property float x");
    ExpectReadError(Write(text), "vertex property 'x' is named twice");
}

TEST_F(PlyErrors, UnsignedIntegerX) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 2 3\n";
    ReplaceOnce(text, "property float x", "property uint x");
    ExpectReadError(Write(text), "vertex property 'x' has type uint");
}

TEST_F(PlyErrors, ShortZ) {
    std::string text = XyzHeader(PlyEncoding::kBinaryBigEndian, 1) + std::string(10, '\0');
    ReplaceOnce(text, "property float z", "property int16 z");
    ExpectReadError(Write(text), "vertex property 'z' has type int16");
}

TEST_F(PlyErrors, ListY) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 1 2 3\n";
    ReplaceOnce(text, "property float y", "property list uchar float y");
    ExpectReadError(Write(text), "vertex property 'y' is a list");
}

TEST_F(PlyErrors, UnknownPropertyType) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 2 3\n";
    ReplaceOnce(text, "property float x", "property float16 x");
    ExpectReadError(Write(text), "line 4: unknown property type 'float16'");
}

TEST_F(PlyErrors, FloatListCount) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 2 3\n";
    ReplaceOnce(text, "end_header",
                "element face 0\nproperty list float int vertex_indices\n"
                "end_header");
    ExpectReadError(Write(text), "line 8: list count type 'float' is not an integer type");
}

TEST_F(PlyErrors, PropertyBeforeElement) {
    ExpectReadError(Write("ply\nformat ascii 1.0\nproperty float x\nend_header\n"),
                    "line 3: property before any element");
}

TEST_F(PlyErrors, UnknownHeaderKeyword) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 2 3\n";
    ReplaceOnce(text, "end_header", "end_headers");
    ExpectReadError(Write(text), "line 7: unknown header keyword 'end_headers'");
}

TEST_F(PlyErrors, MissingEndHeader) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1);
    ReplaceOnce(text, "end_header\n", "");
    ExpectReadError(Write(text), "header has no end_header line");
}

TEST_F(PlyErrors, TruncatedBinaryNamesTheVertex) {
    WritePly(dir_ / "valid.ply", test::RandomCloud(100, 5), PlyEncoding::kBinaryLittleEndian,
             PlyScalar::kFloat64);
    const std::string bytes = ReadFile(dir_ / "valid.ply");
    const std::size_t header_size = bytes.find("end_header\n") + 11;
    ASSERT_EQ(bytes.size(), header_size + 2400);
    ExpectReadError(Write(bytes.substr(0, header_size + 1205)),
                    "binary data truncated in 'vertex' 50: element 'vertex' declares 100 items of "
                    "24 bytes (2400 bytes), but 1205 remain");
}

// More data than the header declares means a wrong count: the points read may be the wrong ones.
TEST_F(PlyErrors, DataBeyondTheDeclaredElementsIsAnError) {
    for (const PlyEncoding encoding : {PlyEncoding::kAscii, PlyEncoding::kBinaryLittleEndian}) {
        const std::string rich = RichFile(encoding);
        const bool ascii = encoding == PlyEncoding::kAscii;
        ExpectReadError(Write(rich + (ascii ? "1 2 3\n" : "\x01\x02")),
                        ascii ? "more data lines than the header's elements declare"
                              : "2 bytes follow the elements the header declares");
        std::string fewer = rich;  // the last vertices read as faces, the faces left over
        ReplaceOnce(fewer, "element vertex 3", "element vertex 2");
        // Binary: vertex 2's bytes read as a face list count run past the end.
        ExpectReadError(Write(fewer),
                        ascii ? "more data lines" : "binary data truncated in 'face' 0 of 2");
    }
    // Trailing blank lines are no data.
    ExpectSameCloud(ReadPly(Write(RichFile(PlyEncoding::kAscii) + "\n  \n")), RichExpected());
}

TEST_F(PlyErrors, TruncatedInsideAVertexList) {
    std::string text = RichFile(PlyEncoding::kBinaryBigEndian);
    const std::size_t sensors = (1 + 1 + 2 * 4 + 8) + (1 + 1 + 8);
    const std::size_t vertices = text.find("end_header\n") + 11 + sensors;
    const std::size_t before_list = 8 + 4 + 3 + 2 + 2;  // x y rgb ring count
    const std::size_t vertex_2 = vertices + (before_list + 4) + (before_list + 3 * 2 + 4);
    // Cut inside the list of vertex 2 (one int16 item); the sizes without lists still fit.
    ExpectReadError(Write(text.substr(0, vertex_2 + before_list + 1)),
                    "binary data truncated in 'vertex' 2 of 3");
}

TEST_F(PlyErrors, TruncatedInAListElementBeforeTheVertices) {
    Body body(PlyEncoding::kBinaryLittleEndian);
    body.Add(std::uint8_t{1}).Add(7);
    body.Add(std::uint8_t{200}).Add(1).Add(2);  // announces 200 items, has 2
    const std::string text =
        "ply\nformat binary_little_endian 1.0\nelement face 2\n"
        "property list uchar int vertex_indices\n" +
        XyzElement(0) + "end_header\n" + body.bytes();
    ExpectReadError(Write(text), "binary data truncated in 'face' 1 of 2");
}

TEST_F(PlyErrors, NegativeListCount) {
    Body body(PlyEncoding::kBinaryLittleEndian);
    body.Add(std::int8_t{-2}).Add(7);
    const std::string text =
        "ply\nformat binary_little_endian 1.0\nelement face 1\n"
        "property list char int vertex_indices\n" +
        XyzElement(0) + "end_header\n" + body.bytes();
    ExpectReadError(Write(text), "negative list count in 'face' 0");
}

TEST_F(PlyErrors, AbsurdCountsAreRejectedBeforeAllocating) {
    Body body(PlyEncoding::kBinaryLittleEndian);
    for (int i = 0; i < 9; ++i) body.Add(static_cast<float>(i));
    ExpectReadError(
        Write(XyzHeader(PlyEncoding::kBinaryLittleEndian, 1'000'000'000'000'000) + body.bytes()),
        "element 'vertex' declares 1000000000000000 items of 12 bytes "
        "(12000000000000000 bytes), but 36 remain");
    ExpectReadError(Write(XyzHeader(PlyEncoding::kAscii, 1'000'000'000'000'000) + "1 2 3\n"),
                    "element 'vertex' declares 1000000000000000 items, more than the");
    std::string faces = XyzHeader(PlyEncoding::kBinaryBigEndian, 0) + body.bytes();
    ReplaceOnce(faces, "element vertex 0",
                "element face 10000000000\nproperty list uint uint vertex_indices\n"
                "element vertex 0");
    ExpectReadError(Write(faces),
                    "element 'face' declares 10000000000 items of at least 4 bytes "
                    "(40000000000 bytes), but 36 remain");
}

TEST_F(PlyErrors, AsciiVertexWithTooFewValues) {
    ExpectReadError(Write(XyzHeader(PlyEncoding::kAscii, 2) + "1 2 3\n4 5\n"),
                    "line 9: vertex 1: too few values (got 2)");
}

TEST_F(PlyErrors, AsciiVertexWithTooManyValues) {
    ExpectReadError(Write(XyzHeader(PlyEncoding::kAscii, 2) + "1 2 3 4\n4 5 6\n"),
                    "line 8: vertex 0: too many values (got 4)");
}

TEST_F(PlyErrors, AsciiNonNumber) {
    ExpectReadError(Write(XyzHeader(PlyEncoding::kAscii, 2) + "1 2 3\n4 x5 6\n"),
                    "line 9: vertex 1: 'x5' is not a number");
}

TEST_F(PlyErrors, AsciiListCountRunsPastTheLine) {
    std::string text = XyzHeader(PlyEncoding::kAscii, 1) + "1 2 5 7 3\n";
    ReplaceOnce(text, "property float z", "property list uchar int ids\nproperty float z");
    ExpectReadError(Write(text), "line 9: vertex 0: too few values (got 5)");
}

TEST_F(PlyErrors, AsciiFileEndsEarly) {
    ExpectReadError(Write(XyzHeader(PlyEncoding::kAscii, 3) + "1 2 3\n4 5 6\n"),
                    "file ends after 2 of 3 vertices");
    std::string text = XyzHeader(PlyEncoding::kAscii, 1);
    ReplaceOnce(text, "element vertex",
                "element face 4\nproperty list uchar int ids\n"
                "element vertex");
    ExpectReadError(Write(text + "3 0 1 2\n"), "file ends in element 'face' after 1 of 4 items");
}

}  // namespace
}  // namespace lidarloop::io

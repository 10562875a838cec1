#include "lidarloop/io/pcd.hpp"

#include <lzf.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdint>
#include <fstream>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/io/detail/binary_io.hpp"
#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {
namespace {

using detail::BytesText;
using detail::CheckedMul;
using detail::DataStream;
using detail::FileSize;
using detail::LineReader;
using detail::LoadLittle;
using detail::Quoted;
using detail::ReadDataBytes;
using detail::StoreLittle;
using detail::ToFloat;

// A 3-byte LZF back reference expands to at most 264 bytes; no valid block grows more than that.
constexpr std::uint64_t kMaxLzfExpansion = 88;

// The DATA line's names, read and written.
constexpr auto kPcdEncodingNames = std::to_array<core::EnumName<PcdEncoding>>({
    {PcdEncoding::kAscii, "ascii"},
    {PcdEncoding::kBinary, "binary"},
    {PcdEncoding::kBinaryCompressed, "binary_compressed"},
});
static_assert(core::IsOneToOne(kPcdEncodingNames));

struct PcdField {
    std::string name;
    std::size_t size = 0;  ///< Bytes per value: 1, 2, 4 or 8.
    char type = 'F';       ///< I (signed), U (unsigned) or F (floating point).
    std::size_t count = 1;

    std::size_t Bytes() const { return size * count; }
    // PCL names padding "_" and leaves it out of binary_compressed blocks.
    bool IsPadding() const { return name == "_"; }
};

// Header values as written, before they are checked against each other.
struct RawPcdHeader {
    std::vector<std::string> names;
    std::vector<std::size_t> sizes;
    std::vector<char> types;
    std::vector<std::size_t> counts;
    std::optional<std::size_t> width;
    std::optional<std::size_t> height;
    std::optional<std::size_t> points;
};

struct PcdHeader {
    std::vector<PcdField> fields;
    std::size_t points = 0;
    PcdEncoding encoding = PcdEncoding::kAscii;
    std::size_t line_count = 0;        ///< Header lines up to and including DATA.
    std::array<std::size_t, 3> xyz{};  ///< Indices of the x, y, z fields.
};

// Where the values of one coordinate lie in a data buffer: value i at offset + i * stride.
struct CoordinateSource {
    std::size_t offset = 0;
    std::size_t stride = 0;
    std::size_t size = 4;  ///< 4 (float) or 8 (double).
};

// ---------------------------------------------------------------------------------------------
// Header

std::size_t ParseHeaderSize(const LineReader& reader, std::string_view keyword,
                            std::string_view token) {
    const auto value = detail::ParseSize(token);
    if (!value) {
        reader.Fail(std::string(keyword) + " value " + Quoted(token) +
                    " is not a non-negative integer");
    }
    return *value;
}

std::vector<std::size_t> ParseHeaderSizes(const LineReader& reader, std::string_view keyword,
                                          std::span<const std::string_view> tokens) {
    std::vector<std::size_t> values;
    for (const auto token : tokens) values.push_back(ParseHeaderSize(reader, keyword, token));
    return values;
}

std::size_t ParseSingleSize(const LineReader& reader, std::string_view keyword,
                            std::span<const std::string_view> tokens) {
    if (tokens.size() != 1) reader.Fail(std::string(keyword) + " needs exactly one value");
    return ParseHeaderSize(reader, keyword, tokens[0]);
}

std::vector<char> ParseTypes(const LineReader& reader, std::span<const std::string_view> tokens) {
    std::vector<char> types;
    for (const auto token : tokens) {
        if (token != "I" && token != "U" && token != "F") {
            reader.Fail("TYPE " + Quoted(token) + " is not I, U or F");
        }
        types.push_back(token[0]);
    }
    return types;
}

void CheckVersion(const LineReader& reader, std::span<const std::string_view> tokens) {
    constexpr std::array<std::string_view, 6> kKnown = {".5", "0.5", ".6", "0.6", ".7", "0.7"};
    if (tokens.size() != 1 || std::find(kKnown.begin(), kKnown.end(), tokens[0]) == kKnown.end()) {
        reader.Fail("unsupported VERSION (expected 0.5, 0.6 or 0.7)");
    }
}

PcdEncoding ParseDataType(const LineReader& reader, std::span<const std::string_view> tokens) {
    if (tokens.size() == 1) {
        if (const auto encoding = core::FindEnum(kPcdEncodingNames, tokens[0])) return *encoding;
    }
    const std::string_view type = tokens.empty() ? std::string_view() : tokens[0];
    reader.Fail("unknown DATA type " + Quoted(type) + " (expected " +
                core::JoinNames(kPcdEncodingNames, " or ") + ")");
}

// Stores one header line in `raw`; returns the encoding when the line is DATA, the last one.
std::optional<PcdEncoding> ParseHeaderLine(const LineReader& reader,
                                           std::span<const std::string_view> tokens,
                                           RawPcdHeader& raw) {
    const std::string_view keyword = tokens[0];
    const auto values = tokens.subspan(1);
    if (keyword == "VERSION") {
        CheckVersion(reader, values);
    } else if (keyword == "FIELDS" || keyword == "COLUMNS") {  // COLUMNS: PCD v0.5
        raw.names.assign(values.begin(), values.end());
    } else if (keyword == "SIZE" || keyword == "COUNT") {
        (keyword == "SIZE" ? raw.sizes : raw.counts) = ParseHeaderSizes(reader, keyword, values);
    } else if (keyword == "TYPE") {
        raw.types = ParseTypes(reader, values);
    } else if (keyword == "WIDTH") {
        raw.width = ParseSingleSize(reader, keyword, values);
    } else if (keyword == "HEIGHT") {
        raw.height = ParseSingleSize(reader, keyword, values);
    } else if (keyword == "POINTS") {
        raw.points = ParseSingleSize(reader, keyword, values);
    } else if (keyword == "DATA") {
        return ParseDataType(reader, values);
    } else if (keyword != "VIEWPOINT") {  // The viewpoint is not applied: points stay as stored.
        reader.Fail("unknown header keyword " + Quoted(keyword) + " (not a PCD file?)");
    }
    return std::nullopt;
}

void CheckEntryCount(const std::filesystem::path& file, const std::string& keyword,
                     std::size_t entries, std::size_t fields) {
    if (entries == 0) throw ReadError(file, "header has no " + keyword + " line");
    if (entries != fields) {
        throw ReadError(file, keyword + " has " + std::to_string(entries) +
                                  " entries but FIELDS has " + std::to_string(fields));
    }
}

PcdField MakeField(const std::filesystem::path& file, const RawPcdHeader& raw, std::size_t i) {
    PcdField field{raw.names[i], raw.sizes[i], raw.types[i], raw.counts[i]};
    if (field.size != 1 && field.size != 2 && field.size != 4 && field.size != 8) {
        throw ReadError(file, "field " + Quoted(field.name) + " has SIZE " +
                                  std::to_string(field.size) + " (expected 1, 2, 4 or 8)");
    }
    if (field.count == 0) throw ReadError(file, "field " + Quoted(field.name) + " has COUNT 0");
    return field;
}

std::size_t CheckPoints(const std::filesystem::path& file, const RawPcdHeader& raw) {
    if (!raw.points) throw ReadError(file, "header has no POINTS line");
    if (raw.width) {
        const std::size_t height = raw.height.value_or(1);
        const auto expected = CheckedMul(*raw.width, height);
        if (!expected || *expected != *raw.points) {
            throw ReadError(file, "POINTS " + std::to_string(*raw.points) +
                                      " does not equal WIDTH*HEIGHT = " +
                                      std::to_string(*raw.width) + "*" + std::to_string(height));
        }
    }
    return *raw.points;
}

// The first few field names, quoted: a header may hold a million of them.
std::string FieldNames(const std::vector<PcdField>& fields) {
    constexpr std::size_t kMaxNames = 8;
    std::string names;
    for (std::size_t i = 0; i < std::min(fields.size(), kMaxNames); ++i) {
        names += (i == 0 ? "" : " ") + Quoted(fields[i].name);
    }
    if (fields.size() > kMaxNames) names += " ... (" + std::to_string(fields.size()) + " fields)";
    return names;
}

std::size_t FindCoordinate(const std::filesystem::path& file, const std::vector<PcdField>& fields,
                           const std::string& name) {
    const auto it = std::find_if(fields.begin(), fields.end(),
                                 [&](const PcdField& field) { return field.name == name; });
    if (it == fields.end()) {
        throw ReadError(file, "no " + Quoted(name) + " field (FIELDS: " + FieldNames(fields) + ")");
    }
    // Which of two the writer meant cannot be told.
    if (std::any_of(it + 1, fields.end(),
                    [&](const PcdField& field) { return field.name == name; }))
        throw ReadError(
            file, "field " + Quoted(name) + " is named twice (FIELDS: " + FieldNames(fields) + ")");
    if (it->type != 'F' || (it->size != 4 && it->size != 8)) {
        throw ReadError(file, "field " + Quoted(name) + " has TYPE " + it->type + " SIZE " +
                                  std::to_string(it->size) +
                                  "; coordinates must be F 4 (float) or F 8 (double)");
    }
    if (it->count != 1) {
        throw ReadError(file, "field " + Quoted(name) + " has COUNT " + std::to_string(it->count) +
                                  " (expected 1)");
    }
    return static_cast<std::size_t>(it - fields.begin());
}

// A corrupt COUNT must neither overflow the record size nor allocate beyond the file: a point
// takes at least 2 bytes per ascii value, its record in binary, 1/88 of that when compressed.
void CheckPointFitsFile(const std::filesystem::path& file, const std::vector<PcdField>& fields,
                        PcdEncoding encoding) {
    const std::size_t file_size = FileSize(file);
    const std::size_t limit =
        encoding == PcdEncoding::kBinaryCompressed ? kMaxLzfExpansion * file_size : file_size;
    std::size_t point_bytes = 0;
    for (const auto& field : fields) {
        const std::size_t per_value = encoding == PcdEncoding::kAscii ? 2 : field.size;
        const auto bytes = CheckedMul(field.count, per_value);
        if (!bytes || *bytes > limit - point_bytes) {
            throw ReadError(file, "field " + Quoted(field.name) + " with COUNT " +
                                      std::to_string(field.count) + " makes one point larger " +
                                      "than the " + std::to_string(file_size) + "-byte file");
        }
        point_bytes += *bytes;
    }
}

PcdHeader BuildHeader(const LineReader& reader, RawPcdHeader raw, PcdEncoding encoding) {
    const auto& file = reader.file();
    if (raw.names.empty()) throw ReadError(file, "header has no FIELDS line");
    if (raw.counts.empty()) raw.counts.assign(raw.names.size(), 1);  // COUNT is optional.
    CheckEntryCount(file, "SIZE", raw.sizes.size(), raw.names.size());
    CheckEntryCount(file, "TYPE", raw.types.size(), raw.names.size());
    CheckEntryCount(file, "COUNT", raw.counts.size(), raw.names.size());
    PcdHeader header;
    for (std::size_t i = 0; i < raw.names.size(); ++i) {
        header.fields.push_back(MakeField(file, raw, i));
    }
    header.points = CheckPoints(file, raw);
    if (header.points > 0) CheckPointFitsFile(file, header.fields, encoding);
    header.encoding = encoding;
    header.line_count = reader.line_number();
    header.xyz = {FindCoordinate(file, header.fields, "x"),
                  FindCoordinate(file, header.fields, "y"),
                  FindCoordinate(file, header.fields, "z")};
    return header;
}

PcdHeader ReadPcdHeader(LineReader& reader) {
    RawPcdHeader raw;
    std::string line;
    while (reader.Next(line)) {
        const auto tokens = detail::SplitFields(line);
        if (tokens.empty() || tokens[0].front() == '#') continue;
        if (const auto encoding = ParseHeaderLine(reader, tokens, raw)) {
            return BuildHeader(reader, std::move(raw), *encoding);
        }
    }
    throw ReadError(reader.file(), "header has no DATA line");
}

// ---------------------------------------------------------------------------------------------
// Data

core::PointCloud GatherPoints(const std::vector<char>& data, std::size_t points,
                              const std::array<CoordinateSource, 3>& sources) {
    core::PointCloud cloud(points);
    for (std::size_t i = 0; i < points; ++i) {
        for (int axis = 0; axis < 3; ++axis) {
            const auto& source = sources[axis];
            const char* bytes = data.data() + source.offset + i * source.stride;
            cloud[i][axis] =
                source.size == 4 ? LoadLittle<float>(bytes) : ToFloat(LoadLittle<double>(bytes));
        }
    }
    return cloud;
}

// Values per ascii line and the positions of x, y, z among them.
struct AsciiLayout {
    std::size_t values = 0;
    std::array<std::size_t, 3> xyz{};
};

AsciiLayout MakeAsciiLayout(const PcdHeader& header) {
    AsciiLayout layout;
    for (std::size_t f = 0; f < header.fields.size(); ++f) {
        for (int axis = 0; axis < 3; ++axis) {
            if (header.xyz[axis] == f) layout.xyz[axis] = layout.values;
        }
        layout.values += header.fields[f].count;
    }
    return layout;
}

core::PointCloud ReadAsciiData(LineReader& reader, const PcdHeader& header) {
    const AsciiLayout layout = MakeAsciiLayout(header);
    const std::size_t values = layout.values;
    core::PointCloud cloud;
    std::vector<double> numbers;
    if (header.points > 0) {  // CheckPointFitsFile bounded `values` for non-empty clouds only.
        // A line holds at least "0 " per value: a lying POINTS must not reserve more than that.
        cloud.reserve(std::min(header.points, FileSize(reader.file()) / (2 * values)));
        numbers.resize(values);
    }
    std::string line;
    while (reader.Next(line)) {
        const auto tokens = detail::SplitFields(line);
        if (tokens.empty()) continue;
        if (cloud.size() == header.points) {
            reader.Fail("more data lines than POINTS " + std::to_string(header.points));
        }
        if (tokens.size() > values) {
            reader.Fail("expected " + std::to_string(values) + " values, got " +
                        std::to_string(tokens.size()));
        }
        reader.ParseNumbers(tokens, values, numbers.data());
        cloud.emplace_back(ToFloat(numbers[layout.xyz[0]]), ToFloat(numbers[layout.xyz[1]]),
                           ToFloat(numbers[layout.xyz[2]]));
    }
    if (cloud.size() < header.points) {
        throw ReadError(reader.file(), "data truncated: POINTS is " +
                                           std::to_string(header.points) + " but the file has " +
                                           std::to_string(cloud.size()) + " data lines");
    }
    return cloud;
}

core::PointCloud ReadBinaryData(const std::filesystem::path& file, DataStream& data,
                                const PcdHeader& header) {
    std::size_t record = 0;
    std::array<CoordinateSource, 3> sources{};
    for (std::size_t f = 0; f < header.fields.size(); ++f) {
        for (int axis = 0; axis < 3; ++axis) {
            if (header.xyz[axis] == f) sources[axis] = {record, 0, header.fields[f].size};
        }
        record += header.fields[f].Bytes();
    }
    for (auto& source : sources) source.stride = record;
    const auto need = CheckedMul(header.points, record);
    if (!need || *need > data.remaining) {
        throw ReadError(file, "data truncated: POINTS " + std::to_string(header.points) + " of " +
                                  std::to_string(record) + " bytes need " + BytesText(need) +
                                  " bytes, but " + std::to_string(data.remaining) +
                                  " follow the header");
    }
    if (*need < data.remaining) {
        throw ReadError(file, std::to_string(data.remaining - *need) + " bytes follow the " +
                                  std::to_string(header.points) +
                                  " points of POINTS: the header's count is wrong");
    }
    return GatherPoints(ReadDataBytes(file, data, *need), header.points, sources);
}

void Decompress(const std::filesystem::path& file, const std::vector<char>& compressed,
                std::vector<char>& out) {
    if (compressed.empty()) throw ReadError(file, "corrupt LZF block: it is empty");
    errno = 0;
    const unsigned produced =
        lzf_decompress(compressed.data(), static_cast<unsigned>(compressed.size()), out.data(),
                       static_cast<unsigned>(out.size()));
    if (produced == 0 && errno == E2BIG) {
        throw ReadError(file, "corrupt LZF block: it decompresses to more than the " +
                                  std::to_string(out.size()) + " bytes stated");
    }
    if (produced == 0) throw ReadError(file, "corrupt LZF block: invalid compressed data");
    if (produced != out.size()) {
        throw ReadError(file, "corrupt LZF block: it decompresses to " + std::to_string(produced) +
                                  " bytes, but its header states " + std::to_string(out.size()));
    }
}

// Checks the 8-byte block header (compressed size, uncompressed size) before anything is
// allocated; returns the compressed size.
std::size_t CheckBlockSizes(const std::filesystem::path& file, const std::vector<char>& sizes,
                            std::size_t remaining, std::size_t expected_size) {
    const std::size_t compressed = LoadLittle<std::uint32_t>(sizes.data());
    const std::size_t uncompressed = LoadLittle<std::uint32_t>(sizes.data() + 4);
    if (compressed > remaining) {
        throw ReadError(file, "data truncated: the compressed block has " +
                                  std::to_string(compressed) + " bytes, but " +
                                  std::to_string(remaining) + " follow its size header");
    }
    if (uncompressed != expected_size) {
        throw ReadError(file, "uncompressed size " + std::to_string(uncompressed) +
                                  " of the binary_compressed block does not match POINTS x "
                                  "record size = " +
                                  std::to_string(expected_size));
    }
    if (uncompressed > kMaxLzfExpansion * compressed) {
        throw ReadError(file, "corrupt LZF block: " + std::to_string(compressed) +
                                  " compressed bytes cannot expand to " +
                                  std::to_string(uncompressed));
    }
    return compressed;
}

core::PointCloud ReadCompressedData(const std::filesystem::path& file, DataStream& data,
                                    const PcdHeader& header) {
    // The block is field-major: all values of the first field, then of the next, ...
    std::size_t packed = 0;
    std::array<CoordinateSource, 3> sources{};
    for (std::size_t f = 0; f < header.fields.size(); ++f) {
        const auto& field = header.fields[f];
        if (field.IsPadding()) continue;
        for (int axis = 0; axis < 3; ++axis) {
            if (header.xyz[axis] == f) sources[axis] = {packed, field.size, field.size};
        }
        packed += field.Bytes();
    }
    const auto expected = CheckedMul(header.points, packed);
    if (!expected || *expected > std::numeric_limits<std::uint32_t>::max()) {
        throw ReadError(file, "POINTS " + std::to_string(header.points) + " of " +
                                  std::to_string(packed) +
                                  " bytes exceed the 4 GiB limit of a binary_compressed block");
    }
    if (data.remaining < 8) {
        throw ReadError(file,
                        "data truncated: the binary_compressed block needs an 8-byte size "
                        "header, but " +
                            std::to_string(data.remaining) + " bytes follow the header");
    }
    const auto sizes = ReadDataBytes(file, data, 8);
    const std::size_t compressed = CheckBlockSizes(file, sizes, data.remaining, *expected);
    if (*expected == 0) return {};
    std::vector<char> unpacked(*expected);
    Decompress(file, ReadDataBytes(file, data, compressed), unpacked);
    for (auto& source : sources) source.offset *= header.points;
    return GatherPoints(unpacked, header.points, sources);
}

// ---------------------------------------------------------------------------------------------
// Writing

std::string_view EncodingName(PcdEncoding encoding) {
    return core::NameOf(kPcdEncodingNames, encoding, "ascii");
}

void WriteHeader(std::ostream& out, std::size_t points, PcdEncoding encoding) {
    out << "# .PCD v0.7 - Point Cloud Data file format\n"
        << "VERSION 0.7\n"
        << "FIELDS x y z\n"
        << "SIZE 4 4 4\n"
        << "TYPE F F F\n"
        << "COUNT 1 1 1\n"
        << "WIDTH " << points << "\n"
        << "HEIGHT 1\n"
        << "VIEWPOINT 0 0 0 1 0 0 0\n"
        << "POINTS " << points << "\n"
        << "DATA " << EncodingName(encoding) << "\n";
}

std::vector<char> PackPoints(const core::PointCloud& cloud, bool field_major) {
    std::vector<char> bytes(cloud.size() * 3 * sizeof(float));
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        for (int axis = 0; axis < 3; ++axis) {
            const std::size_t slot = field_major ? axis * cloud.size() + i : 3 * i + axis;
            StoreLittle(cloud[i][axis], bytes.data() + slot * sizeof(float));
        }
    }
    return bytes;
}

void WriteCompressedPoints(const std::filesystem::path& file, std::ostream& out,
                           const core::PointCloud& cloud) {
    const std::vector<char> planes = PackPoints(cloud, /*field_major=*/true);
    if (planes.size() > std::numeric_limits<std::uint32_t>::max()) {
        throw WriteError(file, "too many points for binary_compressed (its sizes are uint32)");
    }
    // LZF output can exceed its input by about 4 %; this is room enough.
    const std::size_t capacity = std::min<std::size_t>(planes.size() + planes.size() / 16 + 64,
                                                       std::numeric_limits<std::uint32_t>::max());
    std::vector<char> block(8 + capacity);
    unsigned compressed = 0;
    if (!planes.empty()) {
        compressed = lzf_compress(planes.data(), static_cast<unsigned>(planes.size()),
                                  block.data() + 8, static_cast<unsigned>(capacity));
        if (compressed == 0) throw WriteError(file, "LZF compression failed");
    }
    StoreLittle(static_cast<std::uint32_t>(compressed), block.data());
    StoreLittle(static_cast<std::uint32_t>(planes.size()), block.data() + 4);
    out.write(block.data(), static_cast<std::streamsize>(8 + compressed));
}

}  // namespace

core::PointCloud ReadPcd(const std::filesystem::path& file) {
    LineReader reader(file);
    const PcdHeader header = ReadPcdHeader(reader);
    if (header.encoding == PcdEncoding::kAscii) return ReadAsciiData(reader, header);
    DataStream data = detail::OpenDataAfterHeader(file, header.line_count);
    if (header.encoding == PcdEncoding::kBinary) return ReadBinaryData(file, data, header);
    return ReadCompressedData(file, data, header);
}

void WritePcd(const std::filesystem::path& file, const core::PointCloud& cloud,
              PcdEncoding encoding) {
    std::ofstream out = detail::OpenForWriting(file, encoding != PcdEncoding::kAscii);
    WriteHeader(out, cloud.size(), encoding);
    if (encoding == PcdEncoding::kAscii) {
        detail::WriteXyzLines<float>(out, cloud);
    } else if (encoding == PcdEncoding::kBinary) {
        const std::vector<char> bytes = PackPoints(cloud, /*field_major=*/false);
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    } else {
        WriteCompressedPoints(file, out, cloud);
    }
    out.flush();
    if (!out) throw WriteError(file, "write failed");
}

}  // namespace lidarloop::io

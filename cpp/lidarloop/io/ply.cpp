#include "lidarloop/io/ply.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <fstream>
#include <limits>
#include <optional>
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
using detail::FileSize;
using detail::LineReader;
using detail::Load;
using detail::Quoted;
using detail::ToFloat;

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

// Both spellings of each type (PLY 1.0 and the sized names); read only, never written.
constexpr auto kTypeNames = std::to_array<core::EnumName<PlyType>>({
    {PlyType::kInt8, "char"},
    {PlyType::kInt8, "int8"},
    {PlyType::kUint8, "uchar"},
    {PlyType::kUint8, "uint8"},
    {PlyType::kInt16, "short"},
    {PlyType::kInt16, "int16"},
    {PlyType::kUint16, "ushort"},
    {PlyType::kUint16, "uint16"},
    {PlyType::kInt32, "int"},
    {PlyType::kInt32, "int32"},
    {PlyType::kUint32, "uint"},
    {PlyType::kUint32, "uint32"},
    {PlyType::kFloat32, "float"},
    {PlyType::kFloat32, "float32"},
    {PlyType::kFloat64, "double"},
    {PlyType::kFloat64, "float64"},
});

constexpr auto kPlyEncodingNames = std::to_array<core::EnumName<PlyEncoding>>({
    {PlyEncoding::kAscii, "ascii"},
    {PlyEncoding::kBinaryLittleEndian, "binary_little_endian"},
    {PlyEncoding::kBinaryBigEndian, "binary_big_endian"},
});
static_assert(core::IsOneToOne(kPlyEncodingNames));

std::size_t TypeSize(PlyType type) {
    switch (type) {
        case PlyType::kInt8:
        case PlyType::kUint8:
            return 1;
        case PlyType::kInt16:
        case PlyType::kUint16:
            return 2;
        case PlyType::kInt32:
        case PlyType::kUint32:
        case PlyType::kFloat32:
            return 4;
        case PlyType::kFloat64:
            return 8;
    }
    return 8;
}

bool IsFloatingPoint(PlyType type) {
    return type == PlyType::kFloat32 || type == PlyType::kFloat64;
}

struct PlyProperty {
    std::string name;
    std::string type_name;              ///< As written in the header, for messages.
    PlyType type = PlyType::kFloat32;   ///< Scalar type, or item type of a list.
    std::optional<PlyType> count_type;  ///< Set for list properties only.
};

struct PlyElement {
    std::string name;
    std::size_t count = 0;
    std::vector<PlyProperty> properties;

    bool HasLists() const {
        return std::any_of(properties.begin(), properties.end(),
                           [](const PlyProperty& p) { return p.count_type.has_value(); });
    }
    // Bytes of one binary item, counting each list as its count only (zero items).
    std::size_t MinBinaryRowSize() const {
        std::size_t size = 0;
        for (const auto& p : properties) size += TypeSize(p.count_type.value_or(p.type));
        return size;
    }
};

struct PlyHeader {
    PlyEncoding encoding = PlyEncoding::kAscii;
    std::vector<PlyElement> elements;
    std::size_t vertex = 0;      ///< Index of the vertex element.
    std::vector<int> axis_of;    ///< Per vertex property: 0, 1, 2 for x, y, z, else -1.
    std::size_t line_count = 0;  ///< Header lines up to and including end_header.
};

// Byte order of the binary data of a file in `encoding`.
std::endian ByteOrder(PlyEncoding encoding) {
    return encoding == PlyEncoding::kBinaryBigEndian ? std::endian::big : std::endian::little;
}

double LoadScalar(const char* bytes, PlyType type, std::endian order) {
    switch (type) {
        case PlyType::kInt8:
            return Load<std::int8_t>(bytes, order);
        case PlyType::kUint8:
            return Load<std::uint8_t>(bytes, order);
        case PlyType::kInt16:
            return Load<std::int16_t>(bytes, order);
        case PlyType::kUint16:
            return Load<std::uint16_t>(bytes, order);
        case PlyType::kInt32:
            return Load<std::int32_t>(bytes, order);
        case PlyType::kUint32:
            return Load<std::uint32_t>(bytes, order);
        case PlyType::kFloat32:
            return Load<float>(bytes, order);
        case PlyType::kFloat64:
            return Load<double>(bytes, order);
    }
    return 0.0;
}

// ---------------------------------------------------------------------------------------------
// Header

PlyType ParseType(const LineReader& reader, std::string_view name) {
    if (const auto type = core::FindEnum(kTypeNames, name)) return *type;
    reader.Fail("unknown property type " + Quoted(name));
}

PlyEncoding ParseFormat(const LineReader& reader, const std::vector<std::string_view>& tokens) {
    if (tokens.size() != 3) reader.Fail("expected 'format <encoding> 1.0'");
    const auto version = detail::ParseDouble(tokens[2]);
    if (!version || *version != 1.0) reader.Fail("unsupported PLY version " + Quoted(tokens[2]));
    if (const auto encoding = core::FindEnum(kPlyEncodingNames, tokens[1])) return *encoding;
    reader.Fail("unknown format " + Quoted(tokens[1]) + " (expected " +
                core::JoinNames(kPlyEncodingNames, " or ") + ")");
}

PlyElement ParseElement(const LineReader& reader, const std::vector<std::string_view>& tokens) {
    if (tokens.size() != 3) reader.Fail("expected 'element <name> <count>'");
    const auto count = detail::ParseSize(tokens[2]);
    if (!count) {
        reader.Fail("element count " + Quoted(tokens[2]) + " is not a non-negative integer");
    }
    return {std::string(tokens[1]), *count, {}};
}

PlyProperty ParseProperty(const LineReader& reader, const std::vector<std::string_view>& tokens) {
    if (tokens.size() == 3 && tokens[1] != "list") {
        return {std::string(tokens[2]), std::string(tokens[1]), ParseType(reader, tokens[1]), {}};
    }
    if (tokens.size() != 5 || tokens[1] != "list") {
        reader.Fail("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
    }
    const PlyType count_type = ParseType(reader, tokens[2]);
    if (IsFloatingPoint(count_type)) {
        reader.Fail("list count type " + Quoted(tokens[2]) + " is not an integer type");
    }
    return {std::string(tokens[4]), std::string(tokens[3]), ParseType(reader, tokens[3]),
            count_type};
}

std::vector<int> FindCoordinates(const std::filesystem::path& file, const PlyElement& vertex) {
    std::vector<int> axis_of(vertex.properties.size(), -1);
    for (int axis = 0; axis < 3; ++axis) {
        const std::string name(1, "xyz"[axis]);
        const auto it = std::find_if(vertex.properties.begin(), vertex.properties.end(),
                                     [&](const PlyProperty& p) { return p.name == name; });
        if (it == vertex.properties.end()) {
            throw ReadError(file, "element 'vertex' has no '" + name + "' property");
        }
        if (std::any_of(it + 1, vertex.properties.end(),
                        [&](const PlyProperty& p) { return p.name == name; }))
            throw ReadError(file, "vertex property '" + name + "' is named twice");
        if (it->count_type) throw ReadError(file, "vertex property '" + name + "' is a list");
        // Integer coordinates usually carry a scale the file does not state: reading them as
        // metres would be silently wrong.
        if (!IsFloatingPoint(it->type)) {
            throw ReadError(file, "vertex property '" + name + "' has type " + it->type_name +
                                      "; coordinates must be float/float32 or double/float64");
        }
        axis_of[it - vertex.properties.begin()] = axis;
    }
    return axis_of;
}

PlyHeader FinishHeader(const LineReader& reader, std::optional<PlyEncoding> encoding,
                       std::vector<PlyElement> elements) {
    const auto& file = reader.file();
    if (!encoding) throw ReadError(file, "header has no format line");
    const auto vertex = std::find_if(elements.begin(), elements.end(),
                                     [](const PlyElement& e) { return e.name == "vertex"; });
    if (vertex == elements.end()) throw ReadError(file, "header has no 'vertex' element");
    PlyHeader header;
    header.encoding = *encoding;
    header.vertex = static_cast<std::size_t>(vertex - elements.begin());
    header.axis_of = FindCoordinates(file, *vertex);
    header.elements = std::move(elements);
    header.line_count = reader.line_number();
    return header;
}

PlyHeader ReadPlyHeader(LineReader& reader) {
    std::string line;
    if (!reader.Next(line) || detail::SplitFields(line) != std::vector<std::string_view>{"ply"}) {
        throw ReadError(reader.file(), "does not start with 'ply' (not a PLY file)");
    }
    std::optional<PlyEncoding> encoding;
    std::vector<PlyElement> elements;
    while (reader.Next(line)) {
        const auto tokens = detail::SplitFields(line);
        if (tokens.empty()) continue;
        const std::string_view keyword = tokens[0];
        if (keyword == "end_header") return FinishHeader(reader, encoding, std::move(elements));
        if (keyword == "format") {
            encoding = ParseFormat(reader, tokens);
        } else if (keyword == "element") {
            elements.push_back(ParseElement(reader, tokens));
        } else if (keyword == "property") {
            if (elements.empty()) reader.Fail("property before any element");
            elements.back().properties.push_back(ParseProperty(reader, tokens));
        } else if (keyword != "comment" && keyword != "obj_info") {
            reader.Fail("unknown header keyword " + Quoted(keyword));
        }
    }
    throw ReadError(reader.file(), "header has no end_header line");
}

// ---------------------------------------------------------------------------------------------
// ASCII data: one line per element item.

// Each ascii value takes at least two bytes ("0 "); a count beyond that is rejected before any
// memory is reserved for it.
void CheckAsciiCount(const std::filesystem::path& file, const PlyElement& element,
                     std::size_t file_size) {
    const std::size_t min_row = std::max<std::size_t>(1, 2 * element.properties.size());
    if (element.count > file_size / min_row) {
        throw ReadError(file, "element " + Quoted(element.name) + " declares " +
                                  std::to_string(element.count) + " items, more than the " +
                                  std::to_string(file_size) + "-byte file can hold");
    }
}

void SkipAsciiElement(LineReader& reader, const PlyElement& element) {
    std::string line;
    for (std::size_t i = 0; i < element.count; ++i) {
        if (!reader.Next(line)) {
            throw ReadError(reader.file(), "file ends in element " + Quoted(element.name) +
                                               " after " + std::to_string(i) + " of " +
                                               std::to_string(element.count) + " items");
        }
    }
}

Eigen::Vector3f ParseAsciiVertex(const LineReader& reader,
                                 const std::vector<std::string_view>& tokens,
                                 const PlyHeader& header, std::size_t index) {
    const auto fail = [&](const std::string& problem) {
        reader.Fail("vertex " + std::to_string(index) + ": " + problem);
    };
    const auto& properties = header.elements[header.vertex].properties;
    Eigen::Vector3f point = Eigen::Vector3f::Zero();
    std::size_t pos = 0;
    for (std::size_t k = 0; k < properties.size(); ++k) {
        if (pos >= tokens.size()) {
            fail("too few values (got " + std::to_string(tokens.size()) + ")");
        }
        if (properties[k].count_type) {
            const auto count = detail::ParseSize(tokens[pos]);
            if (!count) fail("list count " + Quoted(tokens[pos]) + " is invalid");
            pos += 1 + std::min(*count, tokens.size());  // min: no overflow, still past the end
            continue;
        }
        const auto value = detail::ParseDouble(tokens[pos]);
        if (!value) fail(Quoted(tokens[pos]) + " is not a number");
        if (header.axis_of[k] >= 0) point[header.axis_of[k]] = ToFloat(*value);
        ++pos;
    }
    if (pos != tokens.size()) {
        fail((pos > tokens.size() ? "too few values (got " : "too many values (got ") +
             std::to_string(tokens.size()) + ")");
    }
    return point;
}

core::PointCloud ReadAsciiPly(LineReader& reader, const PlyHeader& header) {
    const std::size_t file_size = FileSize(reader.file());
    for (std::size_t e = 0; e < header.vertex; ++e) {
        CheckAsciiCount(reader.file(), header.elements[e], file_size);
        SkipAsciiElement(reader, header.elements[e]);
    }
    const PlyElement& vertex = header.elements[header.vertex];
    CheckAsciiCount(reader.file(), vertex, file_size);
    core::PointCloud cloud;
    cloud.reserve(vertex.count);
    std::string line;
    while (cloud.size() < vertex.count) {
        if (!reader.Next(line)) {
            throw ReadError(reader.file(), "file ends after " + std::to_string(cloud.size()) +
                                               " of " + std::to_string(vertex.count) + " vertices");
        }
        cloud.push_back(ParseAsciiVertex(reader, detail::SplitFields(line), header, cloud.size()));
    }
    for (std::size_t e = header.vertex + 1; e < header.elements.size(); ++e) {
        CheckAsciiCount(reader.file(), header.elements[e], file_size);
        SkipAsciiElement(reader, header.elements[e]);
    }
    // Lines beyond what the header declares: a count that is wrong, so the points read may be
    // the wrong ones too.
    while (reader.Next(line)) {
        if (!detail::SplitFields(line).empty())
            reader.Fail("more data lines than the header's elements declare");
    }
    return cloud;
}

// ---------------------------------------------------------------------------------------------
// Binary data

class BinaryReader {
public:
    BinaryReader(const std::filesystem::path& file, std::vector<char> bytes, std::endian order)
        : file_(file), bytes_(std::move(bytes)), order_(order) {}

    void SkipElement(const PlyElement& element) {
        CheckFits(element);
        if (!element.HasLists()) {  // Fixed-size items: CheckFits proved they are all there.
            pos_ += element.count * element.MinBinaryRowSize();
            return;
        }
        for (std::size_t i = 0; i < element.count; ++i) {
            for (const auto& property : element.properties) SkipProperty(property, element, i);
        }
    }

    core::PointCloud ReadVertices(const PlyHeader& header) {
        const PlyElement& vertex = header.elements[header.vertex];
        CheckFits(vertex);
        core::PointCloud cloud(vertex.count);  // CheckFits bounds it by the file size.
        for (std::size_t i = 0; i < vertex.count; ++i) {
            for (std::size_t k = 0; k < vertex.properties.size(); ++k) {
                const auto& property = vertex.properties[k];
                const int axis = header.axis_of[k];
                if (axis < 0) {
                    SkipProperty(property, vertex, i);
                } else {
                    const char* bytes = Take(TypeSize(property.type), vertex, i);
                    cloud[i][axis] = ToFloat(LoadScalar(bytes, property.type, order_));
                }
            }
        }
        return cloud;
    }

    // Bytes beyond what the header declares: a count that is wrong, so the points read may be
    // the wrong ones too.
    void RequireEnd() const {
        if (Remaining() == 0) return;
        throw ReadError(
            file_, std::to_string(Remaining()) + " bytes follow the elements the header declares");
    }

private:
    std::size_t Remaining() const { return bytes_.size() - pos_; }

    // Rejects counts the remaining bytes cannot hold before anything is allocated for them.
    void CheckFits(const PlyElement& element) const {
        const std::size_t row = element.MinBinaryRowSize();
        if (row == 0 || element.count <= Remaining() / row) return;
        const bool fixed = !element.HasLists();
        std::string problem = "binary data truncated";
        if (fixed)
            problem += " in " + Quoted(element.name) + " " + std::to_string(Remaining() / row);
        problem += ": element " + Quoted(element.name) + " declares " +
                   std::to_string(element.count) + " items of " + (fixed ? "" : "at least ") +
                   std::to_string(row) + " bytes (" + BytesText(CheckedMul(element.count, row)) +
                   " bytes), but " + std::to_string(Remaining()) + " remain";
        throw ReadError(file_, problem);
    }

    const char* Take(std::size_t size, const PlyElement& element, std::size_t index) {
        if (size > Remaining()) {
            throw ReadError(file_, "binary data truncated in " + Quoted(element.name) + " " +
                                       std::to_string(index) + " of " +
                                       std::to_string(element.count));
        }
        const char* bytes = bytes_.data() + pos_;
        pos_ += size;
        return bytes;
    }

    void SkipProperty(const PlyProperty& property, const PlyElement& element, std::size_t index) {
        if (!property.count_type) {
            Take(TypeSize(property.type), element, index);
            return;
        }
        const double count = LoadScalar(Take(TypeSize(*property.count_type), element, index),
                                        *property.count_type, order_);
        if (count < 0) {
            throw ReadError(file_, "negative list count in " + Quoted(element.name) + " " +
                                       std::to_string(index));
        }
        const auto bytes = CheckedMul(static_cast<std::size_t>(count), TypeSize(property.type));
        Take(bytes.value_or(std::numeric_limits<std::size_t>::max()), element, index);
    }

    std::filesystem::path file_;
    std::vector<char> bytes_;
    std::size_t pos_ = 0;
    std::endian order_ = std::endian::little;
};

// ---------------------------------------------------------------------------------------------
// Writing

std::string_view EncodingName(PlyEncoding encoding) {
    return core::NameOf(kPlyEncodingNames, encoding, "ascii");
}

void WriteHeader(std::ostream& out, std::size_t count, PlyEncoding encoding, PlyScalar scalar) {
    const std::string_view type = scalar == PlyScalar::kFloat32 ? "float" : "double";
    out << "ply\n"
        << "format " << EncodingName(encoding) << " 1.0\n"
        << "comment written by lidarloop\n"
        << "element vertex " << count << "\n"
        << "property " << type << " x\n"
        << "property " << type << " y\n"
        << "property " << type << " z\n"
        << "end_header\n";
}

template <typename T>
void WriteBinaryVertices(std::ostream& out, const core::PointCloud& cloud, std::endian order) {
    std::vector<char> bytes(cloud.size() * 3 * sizeof(T));
    char* next = bytes.data();
    for (const auto& point : cloud) {
        for (int axis = 0; axis < 3; ++axis, next += sizeof(T)) {
            detail::Store(static_cast<T>(point[axis]), next, order);
        }
    }
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

template <typename T>
void WriteVertices(std::ostream& out, const core::PointCloud& cloud, PlyEncoding encoding) {
    if (encoding == PlyEncoding::kAscii) {
        detail::WriteXyzLines<T>(out, cloud);
    } else {
        WriteBinaryVertices<T>(out, cloud, ByteOrder(encoding));
    }
}

}  // namespace

core::PointCloud ReadPly(const std::filesystem::path& file) {
    LineReader reader(file);
    const PlyHeader header = ReadPlyHeader(reader);
    if (header.encoding == PlyEncoding::kAscii) return ReadAsciiPly(reader, header);
    detail::DataStream data = detail::OpenDataAfterHeader(file, header.line_count);
    BinaryReader binary(file, detail::ReadDataBytes(file, data, data.remaining),
                        ByteOrder(header.encoding));
    // Elements after the vertices are never read.
    for (std::size_t e = 0; e < header.vertex; ++e) binary.SkipElement(header.elements[e]);
    core::PointCloud cloud = binary.ReadVertices(header);
    for (std::size_t e = header.vertex + 1; e < header.elements.size(); ++e)
        binary.SkipElement(header.elements[e]);
    binary.RequireEnd();
    return cloud;
}

void WritePly(const std::filesystem::path& file, const core::PointCloud& cloud,
              PlyEncoding encoding, PlyScalar scalar) {
    std::ofstream out = detail::OpenForWriting(file, encoding != PlyEncoding::kAscii);
    WriteHeader(out, cloud.size(), encoding, scalar);
    if (scalar == PlyScalar::kFloat32) {
        WriteVertices<float>(out, cloud, encoding);
    } else {
        WriteVertices<double>(out, cloud, encoding);
    }
    out.flush();
    if (!out) throw WriteError(file, "write failed");
}

}  // namespace lidarloop::io

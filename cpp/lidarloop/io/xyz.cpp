#include "lidarloop/io/xyz.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>

#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/text_parsing.hpp"

namespace lidarloop::io {
namespace {

// Text point files hold no control characters but tabs; naming the first one gives a clear message
// for binary input instead of quoting garbage as "not a number". A '\r' inside a line (old Mac line
// endings) would otherwise glue all points into one line and silently drop all but the first.
void RejectControlCharacters(const detail::LineReader& reader, std::string_view line) {
    const auto bad = std::find_if(line.begin(), line.end(), [](char c) {
        const auto code = static_cast<unsigned char>(c);
        return (code < 0x20 && c != '\t') || code == 0x7f;
    });
    if (bad == line.end()) return;
    char code[8];
    std::snprintf(code, sizeof(code), "0x%02x", static_cast<unsigned char>(*bad));
    reader.Fail(std::string("holds control character ") + code +
                " (binary data?); not a text point file");
}

// Shortest text that reads back as the same float through the double parser the readers use.
// The float's own shortest text nearly always does; where double rounding breaks it
// (7.038531e-26f and its negative, the only such floats in an exhaustive check with libstdc++)
// the double's shortest text is exact.
char* FormatFloat(char* first, char* last, float value) {
    char* end = std::to_chars(first, last, value).ptr;
    const auto parsed = detail::ParseDouble(std::string_view(first, end - first));
    if (std::isnan(value) || (parsed && static_cast<float>(*parsed) == value)) return end;
    return std::to_chars(first, last, static_cast<double>(value)).ptr;
}

bool IsComment(std::string_view first_field) {
    return first_field.starts_with('#') || first_field.starts_with("//");
}

}  // namespace

core::PointCloud ReadXyz(const std::filesystem::path& file) {
    detail::LineReader reader(file);
    core::PointCloud cloud;
    std::string line;
    bool first_data_line = true;
    while (reader.Next(line)) {
        RejectControlCharacters(reader, line);
        const auto fields = detail::SplitFields(line);
        if (fields.empty() || IsComment(fields.front())) continue;
        // Leica .pts files start with the point count on a line of its own.
        const bool is_count_line =
            first_data_line && fields.size() == 1 && detail::ParseSize(fields.front());
        first_data_line = false;
        if (is_count_line) continue;
        double xyz[3];
        // Numbers before the count, so "VERSION 0.7" (a PCD header) reads "'VERSION' is not a
        // number" rather than "got 2".
        reader.ParseNumbers(fields, std::min<std::size_t>(fields.size(), 3), xyz);
        if (fields.size() < 3) reader.ParseNumbers(fields, 3, xyz);
        cloud.emplace_back(static_cast<float>(xyz[0]), static_cast<float>(xyz[1]),
                           static_cast<float>(xyz[2]));
    }
    return cloud;
}

void WriteXyz(const std::filesystem::path& file, const core::PointCloud& cloud) {
    std::ofstream out = detail::OpenForWriting(file, /*binary=*/false);
    std::string line;
    char number[32];
    for (const auto& point : cloud) {
        line.clear();
        for (int axis = 0; axis < 3; ++axis) {
            line.append(number, FormatFloat(number, number + sizeof(number), point[axis]));
            line.push_back(axis < 2 ? ' ' : '\n');
        }
        out << line;
    }
    out.close();
    if (!out) throw WriteError(file, "writing " + std::to_string(cloud.size()) + " points failed");
}

}  // namespace lidarloop::io

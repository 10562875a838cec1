#include "lidarloop/io/detail/text_parsing.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <system_error>

#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io::detail {

std::ifstream OpenForReading(const std::filesystem::path& file, bool binary) {
    std::error_code ec;
    if (!std::filesystem::exists(file, ec)) throw ReadError(file, "no such file");
    if (std::filesystem::is_directory(file, ec)) throw ReadError(file, "is a folder, not a file");
    std::ifstream in(file, binary ? std::ios::binary : std::ios::in);
    if (!in) throw ReadError(file, std::string("cannot open (") + std::strerror(errno) + ")");
    return in;
}

std::ofstream OpenForWriting(const std::filesystem::path& file, bool binary) {
    std::ofstream out(file, binary ? std::ios::binary | std::ios::trunc : std::ios::trunc);
    if (!out) throw WriteError(file, std::string("cannot open (") + std::strerror(errno) + ")");
    return out;
}

std::vector<std::string_view> SplitCsv(std::string_view line) {
    std::vector<std::string_view> fields;
    const auto trim = [](std::string_view f) {
        while (!f.empty() && (f.front() == ' ' || f.front() == '\t')) f.remove_prefix(1);
        while (!f.empty() && (f.back() == ' ' || f.back() == '\t' || f.back() == '\r')) {
            f.remove_suffix(1);
        }
        return f;
    };
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = line.find(',', start);
        fields.push_back(trim(line.substr(start, comma - start)));
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return fields;
}

std::vector<std::string_view> SplitFields(std::string_view line) {
    std::vector<std::string_view> fields;
    const auto is_separator = [](char c) {
        return c == ' ' || c == '\t' || c == ',' || c == '\r' || c == '\n';
    };
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && is_separator(line[i])) ++i;
        const std::size_t start = i;
        while (i < line.size() && !is_separator(line[i])) ++i;
        if (i > start) fields.push_back(line.substr(start, i - start));
    }
    return fields;
}

std::optional<double> ParseDouble(std::string_view token) {
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    if (token.empty()) return std::nullopt;
    double value = 0.0;
    const char* end = token.data() + token.size();
    const auto [ptr, ec] = std::from_chars(token.data(), end, value);
    if (ec != std::errc() || ptr != end) return std::nullopt;
    return value;
}

std::optional<std::size_t> ParseSize(std::string_view token) {
    std::size_t value = 0;
    const char* end = token.data() + token.size();
    const auto [ptr, ec] = std::from_chars(token.data(), end, value);
    if (token.empty() || ec != std::errc() || ptr != end) return std::nullopt;
    return value;
}

std::string ShortNumber(double value) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.3g", value);
    return text;
}

void AppendNumber(std::string& text, double value, char separator) {
    char number[32];
    const auto end = std::to_chars(number, number + sizeof(number), value).ptr;
    text.append(number, end);
    text.push_back(separator);
}

// The float's own shortest text nearly always reads back as the same float through the double
// parser; where double rounding breaks it (7.038531e-26f and its negative, the only such floats in
// an exhaustive check with libstdc++) the double's shortest text is exact.
void AppendFloat(std::string& text, float value, char separator) {
    char number[32];
    char* end = std::to_chars(number, number + sizeof(number), value).ptr;
    const auto parsed = ParseDouble(std::string_view(number, end - number));
    const bool exact = std::isnan(value) || (parsed && static_cast<float>(*parsed) == value);
    if (!exact) end = std::to_chars(number, number + sizeof(number), double{value}).ptr;
    text.append(number, end);
    text.push_back(separator);
}

template <typename T>
void WriteXyzLines(std::ostream& out, const core::PointCloud& cloud) {
    constexpr int kDigits = std::numeric_limits<T>::max_digits10;
    std::array<char, 3 * 32> line{};
    for (const auto& point : cloud) {
        char* end = line.data();
        for (int axis = 0; axis < 3; ++axis) {
            const T value = static_cast<T>(point[axis]);
            end = std::to_chars(end, line.data() + line.size(), value, std::chars_format::general,
                                kDigits)
                      .ptr;
            *end++ = axis < 2 ? ' ' : '\n';
        }
        out.write(line.data(), end - line.data());
    }
}

template void WriteXyzLines<float>(std::ostream& out, const core::PointCloud& cloud);
template void WriteXyzLines<double>(std::ostream& out, const core::PointCloud& cloud);

void WriteTextFile(const std::filesystem::path& file, const std::string& text) {
    std::ofstream out = OpenForWriting(file, /*binary=*/false);
    out << text;
    out.close();
    if (!out) throw WriteError(file, "writing failed");
}

LineReader::LineReader(const std::filesystem::path& file)
    : file_(file), in_(OpenForReading(file, /*binary=*/false)) {}

bool LineReader::Next(std::string& line) {
    if (!std::getline(in_, line)) return false;
    ++line_number_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
}

void LineReader::Fail(const std::string& problem) const {
    throw ReadError(file_, "line " + std::to_string(line_number_) + ": " + problem);
}

void LineReader::ParseNumbers(const std::vector<std::string_view>& fields, std::size_t count,
                              double* out) const {
    if (fields.size() < count) {
        Fail("expected at least " + std::to_string(count) + " numbers, got " +
             std::to_string(fields.size()));
    }
    for (std::size_t i = 0; i < count; ++i) {
        const auto value = ParseDouble(fields[i]);
        if (!value) Fail(Quoted(fields[i]) + " is not a number");
        out[i] = *value;
    }
}

void LineReader::ParseFiniteNumbers(const std::vector<std::string_view>& fields, std::size_t count,
                                    double* out) const {
    ParseNumbers(fields, count, out);
    for (std::size_t i = 0; i < count; ++i) {
        if (!std::isfinite(out[i])) Fail(Quoted(fields[i]) + " is not a finite number");
    }
}

void LineReader::ParseXyz(const std::vector<std::string_view>& fields, double* xyz) const {
    ParseNumbers(fields, std::min<std::size_t>(fields.size(), 3), xyz);
    if (fields.size() < 3) ParseNumbers(fields, 3, xyz);
}

void RejectControlCharacters(const LineReader& reader, std::string_view line,
                             std::string_view file_kind) {
    const auto bad = std::find_if(line.begin(), line.end(), [](char c) {
        const auto code = static_cast<unsigned char>(c);
        return (code < 0x20 && c != '\t') || code == 0x7f;
    });
    if (bad == line.end()) return;
    char code[8];
    std::snprintf(code, sizeof(code), "0x%02x", static_cast<unsigned char>(*bad));
    reader.Fail(std::string("holds control character ") + code + " (binary data?); not a " +
                std::string(file_kind));
}

}  // namespace lidarloop::io::detail

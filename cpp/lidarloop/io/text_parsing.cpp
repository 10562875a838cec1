#include "lidarloop/io/text_parsing.hpp"

#include <cerrno>
#include <charconv>
#include <cstring>
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
        if (!value) Fail("'" + std::string(fields[i]) + "' is not a number");
        out[i] = *value;
    }
}

}  // namespace lidarloop::io::detail

#pragma once

// Internal helpers shared by the readers of text formats. Not installed as public API promise.

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lidarloop::io::detail {

/// Opens `file` for reading; throws ReadError "cannot open (<reason>)" when it does not exist, is
/// a folder or is unreadable.
std::ifstream OpenForReading(const std::filesystem::path& file, bool binary);

/// Opens `file` for writing; throws WriteError when it cannot.
std::ofstream OpenForWriting(const std::filesystem::path& file, bool binary);

/// Splits `line` into fields separated by spaces, tabs, commas or a trailing '\r'.
std::vector<std::string_view> SplitFields(std::string_view line);

/// Parses a whole token as a double ("nan", "inf", a leading '+' accepted); nullopt when the token
/// is not exactly one number.
std::optional<double> ParseDouble(std::string_view token);

/// Parses a whole token as a non-negative integer; nullopt when it is not one.
std::optional<std::size_t> ParseSize(std::string_view token);

/// Reads a text file line by line and keeps the 1-based line number for error messages.
class LineReader {
public:
    explicit LineReader(const std::filesystem::path& file);

    /// Next line without its '\n' (and '\r'); false at the end of the file.
    bool Next(std::string& line);
    std::size_t line_number() const { return line_number_; }
    const std::filesystem::path& file() const { return file_; }

    /// Throws ReadError "<file>: line <n>: <problem>".
    [[noreturn]] void Fail(const std::string& problem) const;

    /// Parses the first `count` fields of `fields` as doubles into `out`; fails naming the line
    /// when there are fewer fields or one is not a number.
    void ParseNumbers(const std::vector<std::string_view>& fields, std::size_t count,
                      double* out) const;

private:
    std::filesystem::path file_;
    std::ifstream in_;
    std::size_t line_number_ = 0;
};

}  // namespace lidarloop::io::detail

#pragma once

// Internal helpers shared by the readers and writers of text formats and of the text headers of
// PCD and PLY. Not installed as public API promise.

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::io::detail {

/// Opens `file` for reading; throws ReadError "cannot open (<reason>)" when it does not exist, is
/// a folder or is unreadable.
std::ifstream OpenForReading(const std::filesystem::path& file, bool binary);

/// Opens `file` for writing; throws WriteError when it cannot.
std::ofstream OpenForWriting(const std::filesystem::path& file, bool binary);

/// Splits `line` into fields separated by spaces, tabs, commas or a trailing '\r'.
std::vector<std::string_view> SplitFields(std::string_view line);

/// Splits `line` at commas, keeping empty fields (lidarloop leaves second_ratio and the pose of
/// an unregistered candidate empty); spaces, tabs and a trailing '\r' around a field trimmed.
std::vector<std::string_view> SplitCsv(std::string_view line);

/// Parses a whole token as a double ("nan", "inf", a leading '+' accepted); nullopt when the token
/// is not exactly one number.
std::optional<double> ParseDouble(std::string_view token);

/// Parses a whole token as a non-negative integer; nullopt when it is not one.
std::optional<std::size_t> ParseSize(std::string_view token);

/// `token` in single quotes for a message, cut when long (core::Quoted).
using core::Quoted;

/// `value` with 3 significant digits ("%.3g") for a message.
std::string ShortNumber(double value);

/// Appends the shortest text that reads back as the same double, then `separator`.
void AppendNumber(std::string& text, double value, char separator);

/// Appends the shortest text that reads back as the same float through ParseDouble and a
/// narrowing to float, then `separator`.
void AppendFloat(std::string& text, float value, char separator);

/// Writes one "x y z" line per point, each coordinate as a T (float or double) with
/// max_digits10 significant digits, so that ParseDouble (narrowed to float) gives back the exact
/// values. For float that is 9 digits, not the shortest form, which can fail to round-trip
/// through the double that ParseDouble reads; 9 digits never do (checked for all 2^32 floats).
template <typename T>
void WriteXyzLines(std::ostream& out, const core::PointCloud& cloud);

/// Writes `text` to `file`; throws WriteError "writing failed".
void WriteTextFile(const std::filesystem::path& file, const std::string& text);

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

    /// ParseNumbers that also fails on "nan" and "inf" ("'<token>' is not a finite number"), for
    /// poses: points may be NaN, poses may not.
    void ParseFiniteNumbers(const std::vector<std::string_view>& fields, std::size_t count,
                            double* out) const;

    /// Parses the first three fields as x, y, z into `xyz`. A non-number among the fields present
    /// is named before a missing field, so a PCD header line "VERSION 0.7" reads "'VERSION' is
    /// not a number" rather than "got 2".
    void ParseXyz(const std::vector<std::string_view>& fields, double* xyz) const;

private:
    std::filesystem::path file_;
    std::ifstream in_;
    std::size_t line_number_ = 0;
};

/// Fails naming the line and the first control character other than a tab in `line`: text files
/// hold none, so one means binary input, which would otherwise be quoted as garbage in a "not a
/// number" message. A '\r' inside a line (old Mac line endings) would otherwise glue all points
/// into one line and silently drop all but the first. The message is "holds control character
/// 0x<hex> (binary data?); not a <file_kind>".
void RejectControlCharacters(const LineReader& reader, std::string_view line,
                             std::string_view file_kind);

}  // namespace lidarloop::io::detail

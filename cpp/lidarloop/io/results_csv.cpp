#include "lidarloop/io/results_csv.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <string_view>

#include "lidarloop/io/detail/text_parsing.hpp"

namespace lidarloop::io {
namespace {

struct Columns {
    std::size_t query = SIZE_MAX;
    std::size_t match = SIZE_MAX;
    std::size_t distance = SIZE_MAX;
};

Columns FindColumns(const detail::LineReader& reader, const std::vector<std::string_view>& names) {
    Columns columns;
    for (std::size_t c = 0; c < names.size(); ++c) {
        if (names[c] == "query") columns.query = c;
        if (names[c] == "match") columns.match = c;
        if (names[c] == "distance") columns.distance = c;
    }
    if (columns.query == SIZE_MAX || columns.match == SIZE_MAX || columns.distance == SIZE_MAX) {
        reader.Fail("the header must name the columns query, match and distance");
    }
    return columns;
}

std::size_t ParseIndex(const detail::LineReader& reader, std::string_view field, const char* name) {
    const auto value = detail::ParseSize(field);
    if (!value) {
        reader.Fail(std::string(name) + " " + detail::Quoted(field) +
                    " is not a scan number (an integer >= 0)");
    }
    return *value;
}

// A number or +inf (the detector rejects the pair, as if it were left out). -inf would be a
// loop at every threshold, below even the sweep's "nothing detected" start, so it is refused.
double ParseDistance(const detail::LineReader& reader, std::string_view field) {
    const auto distance = detail::ParseDouble(field);
    if (!distance || std::isnan(*distance)) {
        reader.Fail("distance " + detail::Quoted(field) + " is not a number");
    }
    if (*distance == -std::numeric_limits<double>::infinity()) {
        reader.Fail("distance " + detail::Quoted(field) +
                    " is -inf; a pair the detector rejects is +inf or left out");
    }
    return *distance;
}

}  // namespace

std::vector<ExternalResult> ReadResultsCsv(const std::filesystem::path& file) {
    detail::LineReader reader(file);
    std::string line;
    if (!reader.Next(line)) reader.Fail("empty file; expected a header line");
    const Columns columns = FindColumns(reader, detail::SplitCsv(line));
    const std::size_t needed = std::max({columns.query, columns.match, columns.distance}) + 1;
    std::vector<ExternalResult> results;
    while (reader.Next(line)) {
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        const auto fields = detail::SplitCsv(line);
        if (fields.size() < needed) {
            reader.Fail("expected at least " + std::to_string(needed) + " columns, got " +
                        std::to_string(fields.size()));
        }
        ExternalResult result;
        result.query = ParseIndex(reader, fields[columns.query], "query");
        result.match = ParseIndex(reader, fields[columns.match], "match");
        result.distance = ParseDistance(reader, fields[columns.distance]);
        result.line = reader.line_number();
        results.push_back(result);
    }
    return results;
}

}  // namespace lidarloop::io

#include "lidarloop/io/xyz.hpp"

#include <string>
#include <string_view>

#include "lidarloop/io/detail/binary_io.hpp"
#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {
namespace {

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
        detail::RejectControlCharacters(reader, line, "text point file");
        const auto fields = detail::SplitFields(line);
        if (fields.empty() || IsComment(fields.front())) continue;
        // Leica .pts files start with the point count on a line of its own.
        const bool is_count_line =
            first_data_line && fields.size() == 1 && detail::ParseSize(fields.front());
        first_data_line = false;
        if (is_count_line) continue;
        double xyz[3];
        reader.ParseXyz(fields, xyz);
        // ToFloat: a plain narrowing is undefined beyond the float range (1e39 in a text file).
        cloud.emplace_back(detail::ToFloat(xyz[0]), detail::ToFloat(xyz[1]),
                           detail::ToFloat(xyz[2]));
    }
    return cloud;
}

void WriteXyz(const std::filesystem::path& file, const core::PointCloud& cloud) {
    std::ofstream out = detail::OpenForWriting(file, /*binary=*/false);
    std::string line;
    for (const auto& point : cloud) {
        line.clear();
        for (int axis = 0; axis < 3; ++axis) {
            detail::AppendFloat(line, point[axis], axis < 2 ? ' ' : '\n');
        }
        out << line;
    }
    out.close();
    if (!out) throw WriteError(file, "writing " + std::to_string(cloud.size()) + " points failed");
}

}  // namespace lidarloop::io

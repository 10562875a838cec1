#include "lidarloop/io/pose_graph_files.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include <Eigen/Geometry>

#include "lidarloop/io/detail/text_parsing.hpp"

namespace lidarloop::io {
namespace {

constexpr std::size_t kMissing = SIZE_MAX;
// detect writes quaternions with 9 digits: a norm further from 1 is an edited or foreign file.
constexpr double kQuaternionNormTolerance = 1e-3;
// The largest acceptance.max_rmse_m (and overlap_radius_m) verification allows: an accepted loop
// never has a larger RMS plane distance.
constexpr double kMaxRmseM = 100.0;
// Scans overlap only within twice the sensor's range (reduction.max_range_m <= 1000 m); 10 km is
// the largest acceptance.max_loop_distance_m.
constexpr double kMaxLoopTranslationM = 1e4;

// Column indices of loops.csv; pose = tx ty tz qx qy qz qw.
struct LoopColumns {
    std::size_t query = kMissing, match = kMissing, accepted = kMissing;
    std::array<std::size_t, 7> pose{kMissing, kMissing, kMissing, kMissing,
                                    kMissing, kMissing, kMissing};
    std::size_t overlap_query = kMissing, overlap_match = kMissing, rmse = kMissing;
    std::size_t distinctive_query = kMissing, distinctive_match = kMissing;
    std::size_t count = 0;
};

LoopColumns FindLoopColumns(const detail::LineReader& reader,
                            const std::vector<std::string_view>& names) {
    static constexpr std::array<std::string_view, 7> kPose = {"tx", "ty", "tz", "qx",
                                                              "qy", "qz", "qw"};
    LoopColumns c;
    c.count = names.size();
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (names[i] == "query") c.query = i;
        if (names[i] == "match") c.match = i;
        if (names[i] == "accepted") c.accepted = i;
        if (names[i] == "overlap_query") c.overlap_query = i;
        if (names[i] == "overlap_match") c.overlap_match = i;
        if (names[i] == "rmse_m") c.rmse = i;
        if (names[i] == "distinctive_query") c.distinctive_query = i;
        if (names[i] == "distinctive_match") c.distinctive_match = i;
        for (std::size_t k = 0; k < kPose.size(); ++k) {
            if (names[i] == kPose[k]) c.pose[k] = i;
        }
    }
    if (c.query == kMissing || c.match == kMissing || c.accepted == kMissing) {
        reader.Fail("the header must name the columns query, match and accepted");
    }
    for (const std::size_t column : c.pose) {
        if (column == kMissing) {
            reader.Fail(
                "the header has no loop pose (tx,ty,tz,qx,qy,qz,qw): a loops.csv of "
                "`detect` with verification is needed (not --no-verify)");
        }
    }
    return c;
}

std::size_t ParseScan(const detail::LineReader& reader, std::string_view field, const char* name,
                      std::size_t scan_count) {
    const auto value = detail::ParseSize(field);
    if (!value) {
        reader.Fail(std::string(name) + " " + detail::Quoted(field) +
                    " is not a scan number (an integer >= 0)");
    }
    if (*value >= scan_count) {
        reader.Fail(std::string(name) + " scan " + std::to_string(*value) +
                    " does not exist (the dataset has " + std::to_string(scan_count) + " scans)");
    }
    return *value;
}

double ParseFinite(const detail::LineReader& reader, std::string_view field, const char* name) {
    const auto value = detail::ParseDouble(field);
    if (!value) reader.Fail(std::string(name) + " " + detail::Quoted(field) + " is not a number");
    if (!std::isfinite(*value)) {
        reader.Fail(std::string(name) + " " + detail::Quoted(field) + " is not a finite number");
    }
    return *value;
}

// An optional column's value in [low, high]; NaN when the column is missing or the field empty.
double ParseOptional(const detail::LineReader& reader, const std::vector<std::string_view>& fields,
                     std::size_t column, const char* name, double low, double high) {
    if (column == kMissing || fields[column].empty()) return std::nan("");
    const double value = ParseFinite(reader, fields[column], name);
    if (value < low || value > high) {
        reader.Fail(std::string(name) + " " + detail::Quoted(fields[column]) + " is outside [" +
                    detail::ShortNumber(low) + ", " + detail::ShortNumber(high) + "]");
    }
    return value;
}

// T_match_query from tx ty tz qx qy qz qw (`v`), or a failure naming what is implausible.
core::Transform LoopPose(const detail::LineReader& reader, const std::array<double, 7>& v) {
    const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);  // Eigen takes w first
    if (std::abs(q.norm() - 1.0) > kQuaternionNormTolerance) {
        reader.Fail("quaternion (qx qy qz qw) has norm " + detail::ShortNumber(q.norm()) +
                    ", expected 1 (within " + detail::ShortNumber(kQuaternionNormTolerance) + ")");
    }
    const Eigen::Vector3d t(v[0], v[1], v[2]);
    if (t.stableNorm() > kMaxLoopTranslationM) {
        reader.Fail("the loop's translation (tx ty tz) is " + detail::ShortNumber(t.stableNorm()) +
                    " m long; scans that far apart cannot overlap (at most " +
                    detail::ShortNumber(kMaxLoopTranslationM) + " m)");
    }
    core::Transform T = core::Transform::Identity();
    T.linear() = q.normalized().toRotationMatrix();
    T.translation() = t;
    return T;
}

LoopRow ParseLoopRow(const detail::LineReader& reader, const std::vector<std::string_view>& f,
                     const LoopColumns& c, std::size_t scan_count) {
    static constexpr std::array<const char*, 7> kNames = {"tx", "ty", "tz", "qx", "qy", "qz", "qw"};
    LoopRow row;
    row.line = reader.line_number();
    row.loop.query = ParseScan(reader, f[c.query], "query", scan_count);
    row.loop.match = ParseScan(reader, f[c.match], "match", scan_count);
    std::array<double, 7> v{};
    for (std::size_t k = 0; k < v.size(); ++k) {
        if (f[c.pose[k]].empty()) reader.Fail("an accepted loop without a pose (empty tx..qw)");
        v[k] = ParseFinite(reader, f[c.pose[k]], kNames[k]);
    }
    row.loop.T_match_query = LoopPose(reader, v);
    // Fractions of points; the distinctive ones are only checked.
    const double overlap_query = ParseOptional(reader, f, c.overlap_query, "overlap_query", 0, 1);
    const double overlap_match = ParseOptional(reader, f, c.overlap_match, "overlap_match", 0, 1);
    ParseOptional(reader, f, c.distinctive_query, "distinctive_query", 0, 1);
    ParseOptional(reader, f, c.distinctive_match, "distinctive_match", 0, 1);
    row.loop.overlap = std::fmin(overlap_query, overlap_match);  // NaN only when both are
    row.loop.rmse_m = ParseOptional(reader, f, c.rmse, "rmse_m", 0, kMaxRmseM);
    return row;
}

void AppendEdge(std::string& text, const posegraph::Edge& edge) {
    text += "EDGE_SE3:QUAT " + std::to_string(edge.from) + ' ' + std::to_string(edge.to) + ' ';
    const Eigen::Vector3d t = edge.T_from_to.translation();
    const Eigen::Quaterniond q = Eigen::Quaterniond(edge.T_from_to.linear()).normalized();
    for (const double value : {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}) {
        detail::AppendNumber(text, value, ' ');
    }
    for (int row = 0; row < 6; ++row) {
        for (int col = row; col < 6; ++col) {
            detail::AppendNumber(text, edge.information(row, col),
                                 row == 5 && col == 5 ? '\n' : ' ');
        }
    }
}

}  // namespace

std::vector<LoopRow> ReadLoopsCsv(const std::filesystem::path& file, std::size_t scan_count) {
    detail::LineReader reader(file);
    std::string line;
    LoopColumns columns;
    bool header = false;
    std::vector<LoopRow> rows;
    while (reader.Next(line)) {
        detail::RejectControlCharacters(reader, line, "loops.csv");
        if (line.empty() || line.front() == '#') continue;
        const std::vector<std::string_view> fields = detail::SplitCsv(line);
        if (!header) {
            columns = FindLoopColumns(reader, fields);
            header = true;
            continue;
        }
        // A query the detector did not verify has no verification columns: fine when it is not
        // an accepted loop.
        const bool short_row = fields.size() < columns.count;
        if (fields.size() > columns.count || (short_row && fields.size() <= columns.accepted)) {
            reader.Fail("expected " + std::to_string(columns.count) +
                        " fields as the header, got " + std::to_string(fields.size()));
        }
        const std::string_view accepted = fields[columns.accepted];
        if (accepted != "0" && accepted != "1") {
            reader.Fail("accepted " + detail::Quoted(accepted) + " is not 0 or 1");
        }
        if (accepted == "1" && short_row) {
            reader.Fail("an accepted loop without a pose (" + std::to_string(fields.size()) +
                        " fields, the header has " + std::to_string(columns.count) + ")");
        }
        if (accepted == "1") rows.push_back(ParseLoopRow(reader, fields, columns, scan_count));
    }
    if (!header) reader.Fail("the file is empty: expected a header naming query,match,accepted");
    return rows;
}

void WriteG2o(const std::filesystem::path& file, const std::vector<core::Transform>& poses,
              const std::vector<posegraph::Edge>& edges,
              const std::vector<posegraph::Edge>& commented_edges) {
    posegraph::RequireEdgesWithin(edges, poses.size());
    posegraph::RequireEdgesWithin(commented_edges, poses.size());
    std::string text = "# lidarloop pose graph: vertices T_world_sensor, edges T_from_to\n";
    for (std::size_t i = 0; i < poses.size(); ++i) {
        text += "VERTEX_SE3:QUAT " + std::to_string(i) + ' ';
        const Eigen::Vector3d t = poses[i].translation();
        const Eigen::Quaterniond q = Eigen::Quaterniond(poses[i].linear()).normalized();
        for (const double value : {t.x(), t.y(), t.z(), q.x(), q.y(), q.z()}) {
            detail::AppendNumber(text, value, ' ');
        }
        detail::AppendNumber(text, q.w(), '\n');
    }
    if (!poses.empty()) text += "FIX 0\n";
    for (const posegraph::Edge& edge : edges) AppendEdge(text, edge);
    for (const posegraph::Edge& edge : commented_edges) {
        text += "# rejected ";
        AppendEdge(text, edge);
    }
    detail::WriteTextFile(file, text);
}

}  // namespace lidarloop::io

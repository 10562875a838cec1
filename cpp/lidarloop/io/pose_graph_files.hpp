#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/posegraph/pose_graph.hpp"

namespace lidarloop::io {

/// An accepted loop read from loops.csv, with the line it came from (for messages).
struct LoopRow {
    posegraph::LoopConstraint loop;
    std::size_t line = 0;
};

/// Reads the accepted loops of a loops.csv written by `lidarloop detect` with verification
/// (docs/cli.md#loopscsv): the rows with accepted = 1, their query and match scans and
/// T_match_query from tx ty tz (metres) and qx qy qz qw; overlap (the smaller of overlap_query
/// and overlap_match) and rmse_m when present. Columns are found by the header, in any order; a
/// row that is not an accepted loop may stop short of them (a query that was not verified).
/// Throws ReadError naming the file and line for a header without query, match, accepted or the
/// pose columns (a loops.csv from `detect --no-verify` has no pose), an accepted row without a
/// pose, a row with more fields than the header, a scan index not below `scan_count`, a
/// non-number, a non-finite value, a quaternion whose norm is not within 1e-3 of 1 (others are
/// normalised), a translation longer than 10 km, an overlap or distinctive fraction outside
/// [0, 1], or an rmse_m outside [0, 100] m (the verification accepts none larger). Rows are
/// returned as they are: duplicates are the caller's to merge.
std::vector<LoopRow> ReadLoopsCsv(const std::filesystem::path& file, std::size_t scan_count);

/// Writes a pose graph in g2o's text format: one `VERTEX_SE3:QUAT id x y z qx qy qz qw` per pose
/// (id = scan index), `FIX 0`, then one `EDGE_SE3:QUAT from to x y z qx qy qz qw` plus the 21
/// entries of the upper triangle of its information matrix, row by row, per edge in `edges`
/// (g2o's order: translation, then the quaternion's x y z; see posegraph::EdgeError). Edges in
/// `commented_edges` (loops the back end rejected) are written after a `# rejected ` prefix, so
/// that g2o skips them. Full double precision. Throws WriteError, and core::ConfigError (before
/// writing) for an edge to a pose beyond `poses`.
void WriteG2o(const std::filesystem::path& file, const std::vector<core::Transform>& poses,
              const std::vector<posegraph::Edge>& edges,
              const std::vector<posegraph::Edge>& commented_edges = {});

}  // namespace lidarloop::io

#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

namespace lidarloop::io {

/// One scored pair from another loop detector's output.
struct ExternalResult {
    std::size_t query = 0;
    std::size_t match = 0;
    /// Smaller = more similar (negate a similarity score first); +inf = rejected, never detected
    double distance = 0.0;
    std::size_t line = 0;  ///< the line of the file it was read from (1: the header), 0: none
};

/// Reads a CSV with a header naming at least the columns `query`, `match` and `distance` (in any
/// order; other columns such as lidarloop's `accepted` are ignored). Indices are scan numbers
/// from 0. Throws ReadError naming the line for a missing column, a non-number, a negative or
/// fractional index, or a NaN or -inf distance.
std::vector<ExternalResult> ReadResultsCsv(const std::filesystem::path& file);

}  // namespace lidarloop::io

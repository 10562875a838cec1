#include "lidarloop/core/scancontext/scancontext_distance.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "lidarloop/core/detail/vector_clones.hpp"
#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

constexpr int kMaxSectors = 720;  // ScanContextConfig::Validate
// The float sums of up to 720 products of unit columns are exact to about 1e-7 each: a smaller
// distance is rounding of equal columns, and reads 0 (equal descriptors are at 0).
constexpr double kRoundingDistance = 2e-6;

// Per shift n, the sum over the rings and the columns m of the candidate of its value at (ring,
// m) times the query's at (ring, m - n): shift n meets query column (m - n) mod S, which is the
// query's reversed row at S - m + n, so for one m all shifts read one contiguous run, and the
// loop over n vectorises. Rows 0..rings-1 add into `cosines` (unit columns: the sum of the
// cosines), row `rings` (occupancy) into `overlaps` (columns occupied in both).
LIDARLOOP_VECTOR_CLONES
void SumOverShifts(const ScanContextColumns& query, const ScanContextColumns& candidate,
                   float* cosines, float* overlaps) {
    const int sectors = query.sectors();
    for (int row = 0; row <= query.rings(); ++row) {
        const float* candidate_row = candidate.ReversedRow(row);
        const float* query_row = query.ReversedRow(row);
        float* sums = row < query.rings() ? cosines : overlaps;
        for (int m = 0; m < sectors; ++m) {
            const float value = candidate_row[sectors - m];  // candidate column m
            if (value == 0.0f) continue;                     // an empty bin adds nothing
            const float* run = query_row + (sectors - m);
            for (int n = 0; n < sectors; ++n) sums[n] += value * run[n];
        }
    }
}

double YawOfShift(int shift, int sectors) {
    const double yaw_rad = 2.0 * std::numbers::pi * shift / sectors;
    return yaw_rad > std::numbers::pi ? yaw_rad - 2.0 * std::numbers::pi : yaw_rad;
}

}  // namespace

ScanContextColumns::ScanContextColumns(const std::vector<float>& bins, int rings, int sectors)
    : rings_(rings),
      sectors_(sectors),
      reversed_(static_cast<std::size_t>(rings + 1) * 2 * static_cast<std::size_t>(sectors), 0.0f) {
    if (rings < 1 || sectors < 1 || bins.size() != static_cast<std::size_t>(rings) * sectors) {
        throw ConfigError("scancontext: " + std::to_string(bins.size()) + " bins for " +
                          std::to_string(rings) + " x " + std::to_string(sectors));
    }
    const auto at = [&](int ring, int column) {
        return bins[static_cast<std::size_t>(ring) * sectors + column];
    };
    for (int column = 0; column < sectors; ++column) {
        double norm_sq = 0.0;
        for (int ring = 0; ring < rings; ++ring)
            norm_sq += double{at(ring, column)} * at(ring, column);
        if (norm_sq == 0.0) continue;  // an empty column: all zero, not occupied
        ++occupied_columns_;
        const double inverse_norm = 1.0 / std::sqrt(norm_sq);
        const auto set = [&](int row, float value) {
            const int k = (sectors - column) % sectors;
            const std::size_t begin = static_cast<std::size_t>(row) * 2 * sectors;
            reversed_[begin + k] = value;
            reversed_[begin + k + sectors] = value;
        };
        for (int ring = 0; ring < rings; ++ring)
            set(ring, static_cast<float>(at(ring, column) * inverse_norm));
        set(rings, 1.0f);
    }
}

ScanContextMatch CompareScanContexts(const ScanContextColumns& query,
                                     const ScanContextColumns& candidate) {
    const int rings = query.rings();
    const int sectors = query.sectors();
    if (candidate.rings() != rings || candidate.sectors() != sectors) {
        throw ConfigError("scancontext: cannot compare a " + std::to_string(rings) + " x " +
                          std::to_string(sectors) + " descriptor with a " +
                          std::to_string(candidate.rings()) + " x " +
                          std::to_string(candidate.sectors()));
    }
    // Per shift n: the sum of cos(c_j^q, c_{j+n}^c) (unit columns; empty ones are 0, so they add
    // nothing) and the number of columns occupied in both (exact in float: counts < 2^24).
    std::array<float, kMaxSectors> cosines{};
    std::array<float, kMaxSectors> overlaps{};
    SumOverShifts(query, candidate, cosines.data(), overlaps.data());
    // The columns occupied in either: a column occupied in one only adds 1 - 0 to the sum.
    const int occupied = query.occupied_columns() + candidate.occupied_columns();
    ScanContextMatch best;
    for (int n = 0; n < sectors; ++n) {
        const double either = occupied - double{overlaps[static_cast<std::size_t>(n)]};
        if (either < 0.5) continue;  // both descriptors empty
        const double distance = 1.0 - double{cosines[static_cast<std::size_t>(n)]} / either;
        if (distance < best.distance) best = {distance, n, 0.0};
    }
    if (best.distance < kRoundingDistance) best.distance = 0.0;
    best.yaw_rad = YawOfShift(best.shift, sectors);
    return best;
}

ScanContextMatch CompareScanContexts(const ScanContext& query, const ScanContext& candidate) {
    return CompareScanContexts(ScanContextColumns(query), ScanContextColumns(candidate));
}

}  // namespace lidarloop::core

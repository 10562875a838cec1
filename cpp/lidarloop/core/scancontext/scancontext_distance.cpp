#include "lidarloop/core/scancontext/scancontext_distance.hpp"

#include <array>
#include <cmath>
#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxSectors = 720;  // ScanContextConfig::Validate

// Adds `value` times the row `reversed` (a ReversedRow of the query) to the per-shift sums for
// candidate column m: shift n meets query column (m - n) mod S, which is reversed[(n - m) mod S],
// so shifts m..S-1 read reversed[0..S-m-1] and shifts 0..m-1 read reversed[S-m..S-1]. Both runs
// are contiguous, so the compiler vectorises them.
void AddShifted(float value, const float* reversed, int m, int sectors, float* sums) {
    float* tail = sums + m;
    for (int k = 0; k < sectors - m; ++k) tail[k] += value * reversed[k];
    const float* wrapped = reversed + (sectors - m);
    for (int n = 0; n < m; ++n) sums[n] += value * wrapped[n];
}

double YawOfShift(int shift, int sectors) {
    const double yaw_rad = 2.0 * kPi * shift / sectors;
    return yaw_rad > kPi ? yaw_rad - 2.0 * kPi : yaw_rad;
}

}  // namespace

ScanContextColumns::ScanContextColumns(const std::vector<float>& bins, int rings, int sectors)
    : rings_(rings),
      sectors_(sectors),
      reversed_(static_cast<std::size_t>(rings + 1) * static_cast<std::size_t>(sectors), 0.0f) {
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
        const int k = (sectors - column) % sectors;
        for (int ring = 0; ring < rings; ++ring) {
            reversed_[static_cast<std::size_t>(ring) * sectors + k] =
                static_cast<float>(at(ring, column) * inverse_norm);
        }
        reversed_[static_cast<std::size_t>(rings) * sectors + k] = 1.0f;
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
    // nothing) and the number of columns occupied in both (the occupancy row, rings + 1).
    std::array<float, kMaxSectors> cosines{};
    std::array<float, kMaxSectors> overlaps{};
    for (int row = 0; row <= rings; ++row) {
        const float* candidate_row = candidate.ReversedRow(row);
        const float* query_row = query.ReversedRow(row);
        float* sums = row < rings ? cosines.data() : overlaps.data();
        for (int m = 0; m < sectors; ++m) {
            const float value = candidate_row[(sectors - m) % sectors];  // candidate column m
            if (value != 0.0f) AddShifted(value, query_row, m, sectors, sums);
        }
    }
    ScanContextMatch best;
    for (int n = 0; n < sectors; ++n) {
        if (overlaps[static_cast<std::size_t>(n)] < 0.5f) continue;  // no common column
        const double distance = 1.0 - double{cosines[static_cast<std::size_t>(n)]} /
                                          double{overlaps[static_cast<std::size_t>(n)]};
        if (distance < best.distance) best = {distance, n, 0.0};
    }
    best.distance = std::max(best.distance, 0.0);  // float rounding of equal columns
    best.yaw_rad = YawOfShift(best.shift, sectors);
    return best;
}

ScanContextMatch CompareScanContexts(const ScanContext& query, const ScanContext& candidate) {
    return CompareScanContexts(ScanContextColumns(query), ScanContextColumns(candidate));
}

}  // namespace lidarloop::core

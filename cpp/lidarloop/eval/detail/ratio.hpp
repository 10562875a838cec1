#pragma once

// Internal: the rates of the metrics and of the per-scan taxonomy. Not installed.

#include <cstdint>

namespace lidarloop::eval::detail {

/// numerator / denominator, 0 for an empty denominator (no case of the kind: no rate to report).
inline double Ratio(std::uint64_t numerator, std::uint64_t denominator) {
    return denominator == 0 ? 0.0
                            : static_cast<double>(numerator) / static_cast<double>(denominator);
}

}  // namespace lidarloop::eval::detail

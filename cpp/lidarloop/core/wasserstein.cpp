#include "lidarloop/core/wasserstein.hpp"

#include <cmath>
#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {

double WassersteinDistance(std::span<const double> g, std::span<const double> h) {
    if (g.size() != h.size() || g.empty()) {
        throw ConfigError(
            "Wasserstein distance needs two histograms with the same, non-zero "
            "number of buckets (got " +
            std::to_string(g.size()) + " and " + std::to_string(h.size()) + ")");
    }
    double prefix_difference = 0.0;
    double total = 0.0;
    for (std::size_t i = 0; i < g.size(); ++i) {
        prefix_difference += g[i] - h[i];
        total += std::abs(prefix_difference);
    }
    return total / static_cast<double>(g.size());
}

}  // namespace lidarloop::core

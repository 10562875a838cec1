#pragma once

#include <span>

namespace lidarloop::core {

/// Discrete 1-D Wasserstein distance of Röhling et al. 2015, eq. (6):
///     W(G, H) = (1/b) * sum_i | sum_{j<=i} (g_j - h_j) |,
/// computed in O(b) with running prefix sums. Both histograms must have the same number b >= 1 of
/// buckets and each sum to 1 (normalised); then 0 <= W <= (b-1)/b < 1 (eq. 8: the last prefix
/// difference is always 0, so the bound 1 is approached for large b but never reached) and W is
/// the earth mover's distance with the value range scaled to [0, 1]. Throws ConfigError when the
/// sizes differ or are zero.
double WassersteinDistance(std::span<const double> g, std::span<const double> h);

/// Röhling eq. (7): the classifier L_tau says "same place" when W <= tau.
inline bool IsLoop(double wasserstein_distance, double tau) { return wasserstein_distance <= tau; }

}  // namespace lidarloop::core

#pragma once

#include <cstddef>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/core/scancontext/scancontext_config.hpp"

namespace lidarloop::core {

/// The Scan Context of one scan (Kim & Kim, IROS 2018, section III-A): an N_r x N_s matrix over
/// polar bins around the sensor. Ring i covers planar ranges [i, i + 1) * L_max / N_r; sector j
/// covers azimuths [j, j + 1) * 360 / N_s degrees, counter-clockwise from the sensor's +x axis.
/// A bin holds the largest height among its points (z + sensor_height_m, metres, at least 0);
/// an empty bin holds 0.
struct ScanContext {
    int rings = 0;
    int sectors = 0;
    std::vector<float> bins;  ///< ring-major: bins[ring * sectors + sector], metres
    /// psi(r_i) = ||r_i||_0 / N_s, the share of ring i's bins that are not 0 (eq. 6): the
    /// yaw-invariant retrieval key.
    std::vector<float> ring_key;
    std::size_t points_used = 0;          ///< finite points within max_range_m
    std::size_t points_skipped = 0;       ///< points with a NaN or Inf coordinate
    std::size_t points_out_of_range = 0;  ///< finite points at a planar range >= max_range_m

    float at(int ring, int sector) const {
        return bins[static_cast<std::size_t>(ring) * static_cast<std::size_t>(sectors) +
                    static_cast<std::size_t>(sector)];
    }
};

/// The Scan Context of `points` (sensor frame, metres). EmptyInputError when no point is finite
/// and within max_range_m; ConfigError for an invalid config. Thread-safe; O(points).
ScanContext ComputeScanContext(PointsView points, const ScanContextConfig& config);

/// The ring key of `bins` (rings x sectors, ring-major): per ring the share of non-zero bins.
std::vector<float> RingKey(const std::vector<float>& bins, int rings, int sectors);

}  // namespace lidarloop::core

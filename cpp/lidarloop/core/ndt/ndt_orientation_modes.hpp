#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace lidarloop::core {

/// A peak of the orientations of a set of lines (the normals of planar NDT cells, or the axes of
/// linear ones): the mean line of the lines near it, and how many they are.
struct OrientationMode {
    Eigen::Vector3d line = Eigen::Vector3d::UnitZ();  ///< unit; a line, so its sign means nothing
    std::size_t count = 0;                            ///< lines within the window around `line`
};

/// The modes of the density of the lines (x[i], y[i], z[i]) (unit vectors; v and -v are the same
/// line), found by mean shift with a flat window of half-angle `window_rad`: from a seed, a
/// direction moves to the principal axis of the lines within the window around it until it stops
/// moving, then on with half the window, so that a second surface inside the window does not pull
/// the mode off the stronger one's normal. Seeds are taken where most lines lie that no mode found
/// so far covers, so every cluster of lines gets its own mode; a mode within `window_rad` of a
/// stronger one is the same cluster and is dropped. A mode is kept only if its window holds more
/// lines than an even spread of the lines no stronger mode explains would put there (a fraction
/// 1 - cos(window_rad) of them), so that scattered noise is no peak while a wall beside a
/// dominant ground is; at least 1% of all lines (fewer are stray cells); and with at least half
/// of them within half the window (a surface's normals gather at its centre; a window of noise
/// reaching into the flank of a surface beside it does not). Sorted by decreasing count (ties:
/// found first). Non-finite and zero vectors are ignored.
///
/// Magnusson et al. 2009 (section II-C) take the peaks of the planar orientation histogram, whose
/// classes are fixed in the sensor frame: one class (~40 degrees wide for p = 9) can hold two
/// surfaces or half of one, depending on how the scan is turned. Modes do not depend on the frame:
/// a mode is a function of the lines alone (rotating every line rotates it), and only which
/// modes are found depends on the frame: seeds come from a fixed binning, so a weak cluster close
/// to a strong one may be reached from one orientation and not from another. `window_rad` in
/// (0, pi/4] (ConfigError otherwise); O(n) in the lines. Thread-safe.
std::vector<OrientationMode> FindOrientationModes(std::span<const float> x,
                                                  std::span<const float> y,
                                                  std::span<const float> z, double window_rad);

}  // namespace lidarloop::core

#pragma once

#include <array>
#include <cstdint>

namespace lidarloop::io {

/// An 8-bit RGB colour.
using Rgb = std::array<std::uint8_t, 3>;

/// The viridis colour map (matplotlib's; perceptually uniform, readable in grey and by
/// colour-blind readers) at `t` in [0, 1]: dark purple at 0, green at 0.5, yellow at 1. `t` is
/// clamped; NaN gives grey. Linear between 9 samples of the original table.
Rgb Viridis(double t);

}  // namespace lidarloop::io

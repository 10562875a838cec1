#include "lidarloop/io/colour_map.hpp"

#include <algorithm>
#include <cmath>

namespace lidarloop::io {

Rgb Viridis(double t) {
    // matplotlib's viridis at 0, 1/8, ..., 1.
    static constexpr std::array<std::array<double, 3>, 9> kSamples{{{68, 1, 84},
                                                                    {71, 44, 122},
                                                                    {59, 81, 139},
                                                                    {44, 113, 142},
                                                                    {33, 144, 141},
                                                                    {39, 173, 129},
                                                                    {92, 200, 99},
                                                                    {170, 220, 50},
                                                                    {253, 231, 37}}};
    if (std::isnan(t)) return {128, 128, 128};
    const double x = std::clamp(t, 0.0, 1.0) * static_cast<double>(kSamples.size() - 1);
    const auto k = std::min(static_cast<std::size_t>(x), kSamples.size() - 2);
    const double f = x - static_cast<double>(k);
    Rgb rgb{};
    for (int c = 0; c < 3; ++c) {
        const double value = kSamples[k][c] * (1.0 - f) + kSamples[k + 1][c] * f;
        rgb[c] = static_cast<std::uint8_t>(std::lround(value));
    }
    return rgb;
}

}  // namespace lidarloop::io

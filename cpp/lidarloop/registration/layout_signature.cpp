#include "lidarloop/registration/layout_signature.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <iterator>
#include <limits>
#include <numbers>

#include "lidarloop/core/angles.hpp"
#include "lidarloop/core/detail/vector_clones.hpp"
#include "lidarloop/registration/coarse_alignment.hpp"
#include "lidarloop/registration/detail/fft2d.hpp"

namespace lidarloop::registration {
namespace {

// The lowest frequencies say how much structure there is, not where.
constexpr int kFirstRadius = 2;
// The norm of the centred log-magnitudes below which they are rounding, not a layout (those of a
// real scan's image are of order 1).
constexpr double kMinContrast = 1e-4;
constexpr std::size_t kSize =
    static_cast<std::size_t>(LayoutSignature::kRadii) * LayoutSignature::kAngles;

// The image geometry of the signature: the coarse search's default cells and grid.
const CoarseConfig& ImageGeometry() {
    static const CoarseConfig geometry;
    return geometry;
}

// Where the polar samples lie in the n x n spectrum (row-major, wrapped), radius-major.
const std::vector<std::size_t>& SampleCells() {
    static const std::vector<std::size_t> cells = [] {
        const int n = ImageGeometry().grid_cells;
        std::vector<std::size_t> result;
        result.reserve(kSize);
        for (int r = 0; r < LayoutSignature::kRadii; ++r) {
            const double radius = kFirstRadius + r;
            for (int a = 0; a < LayoutSignature::kAngles; ++a) {
                const double angle = std::numbers::pi * a / LayoutSignature::kAngles;
                const long x = (std::lround(radius * std::cos(angle)) % n + n) % n;
                const long y = (std::lround(radius * std::sin(angle)) % n + n) % n;
                result.push_back(static_cast<std::size_t>(y * n + x));
            }
        }
        return result;
    }();
    return cells;
}

}  // namespace

LayoutSignature ComputeLayoutSignature(const std::vector<Eigen::Vector3f>& structure_points) {
    LayoutSignature signature;
    if (structure_points.empty()) return signature;
    const int n = ImageGeometry().grid_cells;
    const std::vector<float> image = OccupancyImage(structure_points, 0.0, ImageGeometry());
    std::vector<std::complex<float>> spectrum(image.begin(), image.end());
    detail::Fft2dForward(spectrum, n);
    std::vector<double> values;
    values.reserve(kSize);
    double mean = 0.0;
    for (const std::size_t cell : SampleCells()) {
        values.push_back(std::log1p(static_cast<double>(std::abs(spectrum[cell]))));
        mean += values.back();
    }
    mean /= static_cast<double>(kSize);
    double norm = 0.0;
    for (double& value : values) {
        value -= mean;
        norm += value * value;
    }
    norm = std::sqrt(norm);
    // An image without contrast (one cell: every magnitude 1) differs only by the FFT's rounding.
    if (!(norm > kMinContrast)) return signature;
    signature.values.reserve(kSize);
    for (const double value : values) signature.values.push_back(static_cast<float>(value / norm));
    return signature;
}

namespace {

// Per angle shift, the correlation of `a`'s rows with `b`'s shifted by it, summed over radii.
// Every shift's sum runs over k in order as a scalar loop would, so the result is the same to
// the bit; the shifts are the vector lanes (GCC vectorises the inner loop, no reassociation).
LIDARLOOP_VECTOR_CLONES
std::array<float, LayoutSignature::kAngles> ShiftedCorrelations(const LayoutSignature& a,
                                                                const LayoutSignature& b) {
    constexpr int kAngles = LayoutSignature::kAngles;
    std::array<float, kAngles> shifted{};
    for (int r = 0; r < LayoutSignature::kRadii; ++r) {
        const float* row_a = a.values.data() + static_cast<std::ptrdiff_t>(r) * kAngles;
        const float* row_b = b.values.data() + static_cast<std::ptrdiff_t>(r) * kAngles;
        float doubled[2 * kAngles];
        for (int k = 0; k < kAngles; ++k) doubled[k] = doubled[k + kAngles] = row_b[k];
        float sums[kAngles] = {};
        for (int k = 0; k < kAngles; ++k) {
            const float weight = row_a[k];
            const float* from = doubled + k;
            for (int shift = 0; shift < kAngles; ++shift) sums[shift] += weight * from[shift];
        }
        for (int shift = 0; shift < kAngles; ++shift)
            shifted[static_cast<std::size_t>(shift)] += sums[shift];
    }
    return shifted;
}

bool BothHaveLayouts(const LayoutSignature& a, const LayoutSignature& b) {
    return a.values.size() == kSize && b.values.size() == kSize;
}

}  // namespace

double LayoutSimilarity(const LayoutSignature& a, const LayoutSignature& b) {
    if (!BothHaveLayouts(a, b)) return std::numeric_limits<double>::quiet_NaN();
    const auto shifted = ShiftedCorrelations(a, b);
    return *std::max_element(shifted.begin(), shifted.end());
}

double LayoutYaw(const LayoutSignature& query, const LayoutSignature& match) {
    if (!BothHaveLayouts(query, match)) return std::numeric_limits<double>::quiet_NaN();
    constexpr int kAngles = LayoutSignature::kAngles;
    const auto shifted = ShiftedCorrelations(query, match);
    const auto best = static_cast<int>(
        std::distance(shifted.begin(), std::max_element(shifted.begin(), shifted.end())));
    const auto at = [&](int shift) {
        return static_cast<double>(shifted[static_cast<std::size_t>((shift + kAngles) % kAngles)]);
    };
    const double before = at(best - 1), peak = at(best), after = at(best + 1);
    const double curvature = before - 2.0 * peak + after;
    // The vertex of the parabola through the peak and its neighbours, within half a shift.
    const double offset =
        curvature < 0.0 ? std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5) : 0.0;
    const double step_rad = std::numbers::pi / kAngles;
    const double yaw_rad = (best + offset) * step_rad;
    return std::fmod(yaw_rad + std::numbers::pi, std::numbers::pi);
}

YawWindow LayoutYawWindow(const LayoutSignature& query, const LayoutSignature& match,
                          const CoarseConfig& config) {
    // A NaN centre (no layout) is the whole circle.
    return YawWindow{LayoutYaw(query, match),
                     config.layout_yaw_window_deg * core::kRadiansPerDegree, true};
}

}  // namespace lidarloop::registration

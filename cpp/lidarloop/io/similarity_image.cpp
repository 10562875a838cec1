#include "lidarloop/io/similarity_image.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "lidarloop/core/descriptor.hpp"

namespace lidarloop::io {
namespace {

// Scans per pixel side: 1 up to max_side scans, else the fewest that fit the image in max_side.
std::size_t ScansPerPixel(std::size_t n, int max_side) {
    const auto side = static_cast<std::size_t>(std::max(max_side, 1));
    return std::max<std::size_t>(1, (n + side - 1) / side);
}

// Every pixel (i, j) painted with `shade` of the smallest distance among the pairs of its block
// of scans (the pair itself when a pixel is one scan); the matrix is symmetric, its diagonal 0.
// Shades only ever get darker with smaller distances, so a loop anywhere in a block shows.
template <typename Shade>
Image Paint(const pipeline::SimilarityMatrix& matrix, int max_side, Shade shade) {
    const std::size_t n = matrix.size();
    const std::size_t step = ScansPerPixel(n, max_side);
    const std::size_t side = std::max<std::size_t>((n + step - 1) / step, 1);
    std::vector<float> smallest(side * side, std::numeric_limits<float>::infinity());
    for (std::size_t i = 0; i < n; ++i) smallest[(i / step) * side + i / step] = 0.0f;
    const std::vector<float>& condensed = matrix.condensed();
    std::size_t at = 0;
    for (std::size_t i = 0; i < n; ++i) {
        float* row = smallest.data() + (i / step) * side;
        for (std::size_t j = i + 1; j < n; ++j, ++at) {
            float& pixel = row[j / step];
            pixel = std::min(pixel, condensed[at]);
        }
    }
    Image image{static_cast<int>(side), static_cast<int>(side), 1, {}};
    image.pixels.resize(side * side);
    for (std::size_t r = 0; r < side; ++r) {
        for (std::size_t c = r; c < side; ++c) {
            const std::uint8_t value =
                shade(std::min(smallest[r * side + c], smallest[c * side + r]));
            image.pixels[r * side + c] = value;
            image.pixels[c * side + r] = value;
        }
    }
    return image;
}

// The 95th percentile of the finite distances, over at most ~4 million of them (evenly strided),
// so that a big matrix is not copied whole.
float WhiteDistance(const std::vector<float>& condensed) {
    constexpr std::size_t kMaxSample = std::size_t{1} << 22;
    const std::size_t stride = std::max<std::size_t>(1, condensed.size() / kMaxSample);
    std::vector<float> finite;
    for (std::size_t k = 0; k < condensed.size(); k += stride) {
        if (std::isfinite(condensed[k])) finite.push_back(condensed[k]);
    }
    if (finite.empty()) return 1.0f;
    const auto at = finite.begin() + static_cast<std::ptrdiff_t>(finite.size() * 95 / 100);
    std::nth_element(finite.begin(), at, finite.end());
    return *at > 0.0f ? *at : 1.0f;
}

}  // namespace

Image ThresholdImage(const pipeline::SimilarityMatrix& matrix, core::Method method,
                     double threshold, int max_side) {
    const pipeline::DescriptorMethod& decides = pipeline::MethodOf(method);  // once, not per pair
    return Paint(matrix, max_side, [&](float distance) -> std::uint8_t {
        return decides.IsMatch(distance, threshold) ? 0 : 255;
    });
}

Image DistanceImage(const pipeline::SimilarityMatrix& matrix, int max_side) {
    const float white = WhiteDistance(matrix.condensed());
    return Paint(matrix, max_side, [&](float distance) -> std::uint8_t {
        if (!std::isfinite(distance)) return 255;
        return static_cast<std::uint8_t>(std::lround(255.0f * std::min(1.0f, distance / white)));
    });
}

}  // namespace lidarloop::io

#include "lidarloop/io/similarity_image.hpp"

#include <algorithm>
#include <cmath>

#include "lidarloop/core/descriptor.hpp"

namespace lidarloop::io {
namespace {

// Paints every pixel (i, j) with `shade(distance)`; the matrix is symmetric.
template <typename Shade>
Image Paint(const pipeline::SimilarityMatrix& matrix, Shade shade) {
    const auto n = static_cast<int>(matrix.size());
    Image image{std::max(n, 1), std::max(n, 1), 1, {}};
    image.pixels.assign(static_cast<std::size_t>(image.width) * image.height, 255);
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            image.pixels[static_cast<std::size_t>(i) * n + j] =
                shade(matrix.at(static_cast<std::size_t>(i), static_cast<std::size_t>(j)));
        }
    }
    return image;
}

}  // namespace

Image ThresholdImage(const pipeline::SimilarityMatrix& matrix, core::Method method,
                     double threshold) {
    const pipeline::DescriptorMethod& decides = pipeline::MethodOf(method);  // once, not per pair
    return Paint(matrix, [&](float distance) -> std::uint8_t {
        return decides.IsMatch(distance, threshold) ? 0 : 255;
    });
}

Image DistanceImage(const pipeline::SimilarityMatrix& matrix) {
    std::vector<float> finite;
    for (float d : matrix.condensed()) {
        if (std::isfinite(d)) finite.push_back(d);
    }
    float white = 1.0f;
    if (!finite.empty()) {
        const auto at = finite.begin() + static_cast<std::ptrdiff_t>(finite.size() * 95 / 100);
        std::nth_element(finite.begin(), at, finite.end());
        white = *at > 0.0f ? *at : 1.0f;
    }
    return Paint(matrix, [&](float distance) -> std::uint8_t {
        if (!std::isfinite(distance)) return 255;
        return static_cast<std::uint8_t>(std::lround(255.0f * std::min(1.0f, distance / white)));
    });
}

}  // namespace lidarloop::io

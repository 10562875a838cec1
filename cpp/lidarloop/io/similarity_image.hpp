#pragma once

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/io/png.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

namespace lidarloop::io {

/// Largest width and height of a similarity image, pixels: a person cannot read more, and a
/// 20,000-pixel PNG took a minute to write.
inline constexpr int kMaxImageSide = 2000;

/// The similarity matrix as the papers draw it (Röhling figs. 5-7, Magnusson fig. 3c): one pixel
/// per scan pair, black where the pair is a match under `threshold` (W <= tau, sigma' < t_d),
/// white elsewhere; scan 0 at the top left. A matrix of more than `max_side` scans is drawn in
/// square blocks of ceil(n / max_side) scans a pixel, black when any pair of the block matches.
Image ThresholdImage(const pipeline::SimilarityMatrix& matrix, core::Method method,
                     double threshold, int max_side = kMaxImageSide);

/// Grey-scale distances: black = 0, white = the 95th percentile of the finite distances or
/// more (of an even sample of 4 million for big matrices); missing scans white. Blocks as
/// ThresholdImage, each pixel the smallest distance of its block.
Image DistanceImage(const pipeline::SimilarityMatrix& matrix, int max_side = kMaxImageSide);

}  // namespace lidarloop::io

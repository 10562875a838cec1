#pragma once

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/io/png.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

namespace lidarloop::io {

/// The similarity matrix as the papers draw it (Röhling figs. 5-7, Magnusson fig. 3c): one pixel
/// per scan pair, black where the pair is a match under `threshold` (W <= tau, sigma' < t_d),
/// white elsewhere; scan 0 at the top left.
Image ThresholdImage(const pipeline::SimilarityMatrix& matrix, core::Method method,
                     double threshold);

/// Grey-scale distances: black = 0, white = the 95th percentile of the finite distances or
/// more; missing scans white.
Image DistanceImage(const pipeline::SimilarityMatrix& matrix);

}  // namespace lidarloop::io

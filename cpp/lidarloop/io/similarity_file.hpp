#pragma once

#include <filesystem>

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

namespace lidarloop::io {

/// A similarity matrix as read back from its file.
struct StoredSimilarity {
    core::Method method = core::Method::kHeight;
    pipeline::SimilarityMatrix matrix;
};

/// Writes the condensed upper triangle as a compact binary file: "LLSIM001", the method name,
/// n (uint64), then n(n-1)/2 float32 distances, all little-endian (4 bytes per scan pair).
void WriteSimilarityMatrix(const std::filesystem::path& file,
                           const pipeline::SimilarityMatrix& matrix, core::Method method);

/// Reads a file written by WriteSimilarityMatrix; ReadError for a wrong magic, an unknown
/// method, a size that does not match n, or trailing bytes.
StoredSimilarity ReadSimilarityMatrix(const std::filesystem::path& file);

}  // namespace lidarloop::io

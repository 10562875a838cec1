#include "lidarloop/pipeline/similarity_matrix.hpp"

#include <algorithm>
#include <stdexcept>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

namespace lidarloop::pipeline {
namespace {

constexpr std::size_t kTile = 128;  // 128 rows of 416 bytes: both tiles fit in L2

void FillTile(const DescriptorDatabase& database, std::size_t row_begin, std::size_t row_end,
              std::size_t col_begin, std::size_t col_end, SimilarityMatrix& matrix) {
    for (std::size_t i = row_begin; i < row_end; ++i) {
        for (std::size_t j = std::max(col_begin, i + 1); j < col_end; ++j) {
            matrix.set(i, j, static_cast<float>(database.Distance(i, j)));
        }
    }
}

}  // namespace

SimilarityMatrix::SimilarityMatrix(std::size_t n) : n_(n), values_(n > 1 ? n * (n - 1) / 2 : 0) {}

float SimilarityMatrix::at(std::size_t i, std::size_t j) const {
    if (i >= n_ || j >= n_) throw std::out_of_range("similarity matrix index out of range");
    if (i == j) return 0.0f;
    return i < j ? values_[Index(i, j)] : values_[Index(j, i)];
}

SimilarityMatrix ComputeSimilarityMatrix(const DescriptorDatabase& database, Execution execution) {
    const std::size_t n = database.size();
    SimilarityMatrix matrix(n);
    if (execution == Execution::kSerial) {
        FillTile(database, 0, n, 0, n, matrix);
        return matrix;
    }
    const std::size_t tiles = (n + kTile - 1) / kTile;
    tbb::parallel_for(tbb::blocked_range2d<std::size_t>(0, tiles, 1, 0, tiles, 1),
                      [&](const tbb::blocked_range2d<std::size_t>& range) {
                          for (std::size_t ti = range.rows().begin(); ti < range.rows().end();
                               ++ti) {
                              for (std::size_t tj = std::max(ti, range.cols().begin());
                                   tj < range.cols().end(); ++tj) {
                                  FillTile(database, ti * kTile, std::min(n, (ti + 1) * kTile),
                                           tj * kTile, std::min(n, (tj + 1) * kTile), matrix);
                              }
                          }
                      });
    return matrix;
}

}  // namespace lidarloop::pipeline

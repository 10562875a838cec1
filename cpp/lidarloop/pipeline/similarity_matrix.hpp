#pragma once

#include <cstddef>
#include <vector>

#include "lidarloop/pipeline/descriptor_database.hpp"

namespace lidarloop::pipeline {

/// The distances between all pairs of scans of a sequence (Röhling figs. 5-7, Magnusson fig. 3c),
/// stored as the condensed upper triangle (n(n-1)/2 floats): the matrix is symmetric with a zero
/// diagonal. Entries of missing scans are +inf.
class SimilarityMatrix {
public:
    explicit SimilarityMatrix(std::size_t n = 0);

    std::size_t size() const { return n_; }
    float at(std::size_t i, std::size_t j) const;
    void set(std::size_t i, std::size_t j, float distance) { values_[Index(i, j)] = distance; }
    const std::vector<float>& condensed() const { return values_; }
    std::vector<float>& condensed() { return values_; }

    /// Position of the pair i < j in condensed().
    std::size_t Index(std::size_t i, std::size_t j) const {
        return i * (2 * n_ - i - 1) / 2 + (j - i - 1);
    }

private:
    std::size_t n_;
    std::vector<float> values_;
};

enum class Execution { kSerial, kParallel };

/// All pairwise distances of `database`. kParallel splits the upper triangle into tiles of rows
/// and columns (each tile's rows stay in cache) over oneTBB's threads; both executions compute
/// every entry with the same arithmetic, so their results are identical.
SimilarityMatrix ComputeSimilarityMatrix(const DescriptorDatabase& database,
                                         Execution execution = Execution::kParallel);

}  // namespace lidarloop::pipeline

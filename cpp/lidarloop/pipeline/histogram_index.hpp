#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "lidarloop/pipeline/cumulative_histograms.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::pipeline {

/// Exact nearest-neighbour search over the rows of a CumulativeHistograms store under Röhling's
/// W, an L1 distance on cumulative histograms.
///
/// Why not a k-d tree: at b = 100 dimensions a k-d tree visits nearly every leaf. Instead the
/// index uses lower bounds that hold for L1 and cost far less than a full comparison:
///   |sum(a) - sum(b)|  <=  sum over blocks |block sum(a) - block sum(b)|  <=  ||a - b||_1.
/// Rows are kept sorted by their total sum; a query walks outwards from its own total, in both
/// directions, stops a direction once the first bound exceeds the k-th best distance so far,
/// skips rows whose block bound exceeds it, and compares the rest in full. The result is exactly
/// the brute-force top k (ties broken by the smaller index); rounding of the float kernel is
/// covered by a relative slack of 1e-5 on the bounds.
///
/// Memory: 4 + 4 * kBlocks bytes per row besides the store. Insert is O(n) (a sorted vector),
/// Search is O(n) in the worst case and typically touches a small fraction of the rows.
class HistogramIndex {
public:
    static constexpr int kBlocks = 8;

    /// Indexes `store`, which must outlive the index; rows added to it later are not indexed
    /// until Insert is called for them.
    explicit HistogramIndex(const CumulativeHistograms& store);

    /// Indexes row `id` of the store (rows may be indexed in any order, each once).
    void Insert(std::size_t id);
    /// Indexes every row of the store not yet indexed for which `include(id)` holds (all when
    /// empty), at once (O(n log n)).
    void InsertAll(const std::function<bool(std::size_t)>& include = {});
    std::size_t size() const { return sorted_.size(); }

    /// The k rows nearest to `query_row` (a row made by the store's MakeRow) among the indexed
    /// rows for which `eligible(id)` is true (all when empty), sorted by (distance, index).
    std::vector<Neighbor> Search(const float* query_row, std::size_t k,
                                 const std::function<bool(std::size_t)>& eligible = {}) const;

    /// The same by comparing every eligible row (the reference the index is tested against).
    std::vector<Neighbor> BruteForce(const float* query_row, std::size_t k,
                                     const std::function<bool(std::size_t)>& eligible = {}) const;

private:
    struct Key {
        double total;  // sum of the row
        std::size_t id;
    };
    void ComputeBlocks(const float* row, float* blocks, double& total) const;

    const CumulativeHistograms& store_;
    std::vector<Key> sorted_;    // by total
    std::vector<float> blocks_;  // kBlocks per store row (by id)
    std::vector<std::uint8_t> indexed_;
    int block_size_;
};

}  // namespace lidarloop::pipeline

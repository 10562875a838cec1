#include "lidarloop/pipeline/histogram_index.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "lidarloop/core/error.hpp"

namespace lidarloop::pipeline {
namespace {

constexpr double kSlack = 1.0 - 1e-5;  // bounds are shrunk by this before pruning

// The k best so far, kept sorted by (distance, index); distances in L1 units.
class TopK {
public:
    explicit TopK(std::size_t k) : k_(k) {}
    double Worst() const {
        return best_.size() < k_ ? std::numeric_limits<double>::infinity() : best_.back().distance;
    }
    void Offer(std::size_t id, double distance) {
        const auto before = [](const Neighbor& a, const Neighbor& b) {
            return a.distance < b.distance || (a.distance == b.distance && a.index < b.index);
        };
        const Neighbor candidate{id, distance};
        if (best_.size() == k_ && !before(candidate, best_.back())) return;
        best_.insert(std::upper_bound(best_.begin(), best_.end(), candidate, before), candidate);
        if (best_.size() > k_) best_.pop_back();
    }
    // Converts L1 to W by the same division CumulativeHistograms::Distance does.
    std::vector<Neighbor> Take(double bins) {
        for (Neighbor& n : best_) n.distance /= bins;
        return std::move(best_);
    }

private:
    std::size_t k_;
    std::vector<Neighbor> best_;
};

}  // namespace

HistogramIndex::HistogramIndex(const CumulativeHistograms& store)
    : store_(store), block_size_((store.stride() + kBlocks - 1) / kBlocks) {}

void HistogramIndex::ComputeBlocks(const float* row, float* blocks, double& total) const {
    total = 0.0;
    for (int b = 0; b < kBlocks; ++b) {
        double block = 0.0;
        const int end = std::min(store_.stride(), (b + 1) * block_size_);
        for (int k = b * block_size_; k < end; ++k) block += row[k];
        blocks[b] = static_cast<float>(block);
        total += block;
    }
}

void HistogramIndex::Insert(std::size_t id) {
    if (id >= store_.size())
        throw core::ConfigError("HistogramIndex: row " + std::to_string(id) +
                                " is not in the store");
    if (indexed_.size() < store_.size()) {
        indexed_.resize(store_.size(), 0);
        blocks_.resize(store_.size() * kBlocks, 0.0f);
    }
    if (indexed_[id]) throw core::ConfigError("HistogramIndex: row indexed twice");
    indexed_[id] = 1;
    Key key{0.0, id};
    ComputeBlocks(store_.Row(id), &blocks_[id * kBlocks], key.total);
    const auto by_total = [](const Key& a, const Key& b) { return a.total < b.total; };
    sorted_.insert(std::upper_bound(sorted_.begin(), sorted_.end(), key, by_total), key);
}

void HistogramIndex::InsertAll(const std::function<bool(std::size_t)>& include) {
    indexed_.resize(store_.size(), 0);
    blocks_.resize(store_.size() * kBlocks, 0.0f);
    for (std::size_t id = 0; id < store_.size(); ++id) {
        if (indexed_[id] || (include && !include(id))) continue;
        indexed_[id] = 1;
        Key key{0.0, id};
        ComputeBlocks(store_.Row(id), &blocks_[id * kBlocks], key.total);
        sorted_.push_back(key);
    }
    std::sort(sorted_.begin(), sorted_.end(),
              [](const Key& a, const Key& b) { return a.total < b.total; });
}

std::vector<Neighbor> HistogramIndex::Search(
    const float* query_row, std::size_t k, const std::function<bool(std::size_t)>& eligible) const {
    TopK best(k);
    if (k == 0 || sorted_.empty()) return best.Take(1.0);
    float query_blocks[kBlocks];
    double query_total = 0.0;
    ComputeBlocks(query_row, query_blocks, query_total);
    const auto consider = [&](const Key& key) {
        if (eligible && !eligible(key.id)) return;
        const float* blocks = &blocks_[key.id * kBlocks];
        double bound = 0.0;
        for (int b = 0; b < kBlocks; ++b) bound += std::abs(double{query_blocks[b]} - blocks[b]);
        if (bound * kSlack > best.Worst()) return;
        best.Offer(key.id,
                   CumulativeHistograms::L1(query_row, store_.Row(key.id), store_.stride()));
    };
    // Walk outwards from the query's total: `up` over larger totals, `down` over smaller ones.
    auto up = std::lower_bound(sorted_.begin(), sorted_.end(), query_total,
                               [](const Key& key, double total) { return key.total < total; });
    auto down = up;
    while (up != sorted_.end() || down != sorted_.begin()) {
        const double gap_up =
            up != sorted_.end() ? up->total - query_total : std::numeric_limits<double>::infinity();
        const double gap_down = down != sorted_.begin() ? query_total - (down - 1)->total
                                                        : std::numeric_limits<double>::infinity();
        if (std::min(gap_up, gap_down) * kSlack > best.Worst()) break;
        if (gap_up <= gap_down) {
            consider(*up++);
        } else {
            consider(*--down);
        }
    }
    return best.Take(store_.bins());
}

std::vector<Neighbor> HistogramIndex::BruteForce(
    const float* query_row, std::size_t k, const std::function<bool(std::size_t)>& eligible) const {
    TopK best(k);
    if (k == 0) return best.Take(1.0);
    for (const Key& key : sorted_) {
        if (eligible && !eligible(key.id)) continue;
        best.Offer(key.id,
                   CumulativeHistograms::L1(query_row, store_.Row(key.id), store_.stride()));
    }
    return best.Take(store_.bins());
}

}  // namespace lidarloop::pipeline

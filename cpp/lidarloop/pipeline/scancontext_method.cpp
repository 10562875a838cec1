#include "lidarloop/pipeline/scancontext_method.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"

namespace lidarloop::pipeline {
namespace {

using core::ScanContext;
using core::ScanContextColumns;

// A scan as compared: its unit columns and its ring key.
struct ScanContextQuery : PreparedQuery {
    ScanContextColumns columns;
    std::vector<float> ring_key;
};

const ScanContextQuery& QueryOf(const PreparedQuery& query) {
    return static_cast<const ScanContextQuery&>(query);
}

double RingKeyDistanceSq(const std::vector<float>& a, const std::vector<float>& b) {
    double sum = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const double d = double{a[i]} - b[i];
        sum += d * d;
    }
    return sum;
}

class ScanContextStore : public DescriptorStore {
public:
    explicit ScanContextStore(const core::ScanContextConfig& config) : config_(config) {}

    const core::ScanContextConfig& config() const { return config_; }
    std::size_t size() const { return bins_.size(); }
    const std::vector<float>& RingKeyOf(std::size_t i) const { return ring_keys_[i]; }

    std::unique_ptr<DescriptorStore> Clone() const override {
        return std::make_unique<ScanContextStore>(*this);
    }
    void Add(const core::Descriptor& descriptor) override {
        AddBins(descriptor.As<ScanContext>().bins);
    }
    void AddMissing() override {
        bins_.emplace_back();
        columns_.emplace_back();
        ring_keys_.emplace_back();
    }
    double Distance(std::size_t i, std::size_t j) const override {
        return core::CompareScanContexts(columns_[i], columns_[j]).distance;
    }
    std::unique_ptr<PreparedQuery> Prepare(const core::Descriptor& descriptor) const override {
        const ScanContext& sc = descriptor.As<ScanContext>();
        CheckShape(sc.bins);
        auto query = std::make_unique<ScanContextQuery>();
        query->columns = ScanContextColumns(sc);
        query->ring_key = sc.ring_key;
        return query;
    }
    std::unique_ptr<PreparedQuery> PrepareStored(std::size_t i) const override {
        auto query = std::make_unique<ScanContextQuery>();
        query->columns = columns_[i];
        query->ring_key = ring_keys_[i];
        return query;
    }
    double Distance(const PreparedQuery& query, std::size_t j) const override {
        return core::CompareScanContexts(QueryOf(query).columns, columns_[j]).distance;
    }
    std::unique_ptr<NeighborIndex> MakeIndex() const override;

    // The bins, placeholders included (all zero): rings x sectors floats.
    void Encode(std::size_t i, core::ByteWriter& out) const override {
        std::vector<float> bins = bins_[i];
        bins.resize(BinCount(), 0.0f);
        out.PutArray(bins.data(), bins.size());
    }
    void Decode(core::ByteReader& in, bool valid) override {
        std::vector<float> bins(BinCount());
        in.GetArray(bins.data(), bins.size(), "scan context bins");
        if (!std::all_of(bins.begin(), bins.end(), [](float v) { return std::isfinite(v); }))
            in.Fail("scan context bins are not all finite");
        if (valid) {
            AddBins(std::move(bins));
        } else {
            AddMissing();
        }
    }

private:
    std::size_t BinCount() const {
        return static_cast<std::size_t>(config_.rings) * static_cast<std::size_t>(config_.sectors);
    }
    void CheckShape(const std::vector<float>& bins) const {
        if (bins.size() != BinCount()) {
            throw core::ConfigError("scancontext: a descriptor of " + std::to_string(bins.size()) +
                                    " bins in a database of " + std::to_string(config_.rings) +
                                    " x " + std::to_string(config_.sectors));
        }
    }
    void AddBins(std::vector<float> bins) {
        CheckShape(bins);
        columns_.emplace_back(bins, config_.rings, config_.sectors);
        ring_keys_.push_back(core::RingKey(bins, config_.rings, config_.sectors));
        bins_.push_back(std::move(bins));
    }

    core::ScanContextConfig config_;
    std::vector<std::vector<float>> bins_;  // as described, for Encode; empty for placeholders
    std::vector<ScanContextColumns> columns_;
    std::vector<std::vector<float>> ring_keys_;
};

// The paper's two-stage retrieval (section III-C): the scans with the nearest ring keys (L2),
// then ranked by the full distance. Approximate: a scan whose ring key is far can be nearer by
// the full distance, and is then missed.
class RingKeyIndex : public NeighborIndex {
public:
    RingKeyIndex(const ScanContextStore& store, std::size_t candidates)
        : store_(store), candidates_(candidates) {}

    void Insert(std::size_t id) override {
        if (id >= indexed_.size()) indexed_.resize(id + 1, 0);
        indexed_[id] = 1;
    }
    void InsertAll(const std::function<bool(std::size_t)>& include) override {
        for (std::size_t id = 0; id < store_.size(); ++id) {
            if (!include || include(id)) Insert(id);
        }
    }
    std::vector<Neighbor> Search(const PreparedQuery& query, std::size_t k,
                                 const std::function<bool(std::size_t)>& eligible) const override {
        const ScanContextQuery& q = QueryOf(query);
        std::vector<Neighbor> found = NearestCandidates(
            indexed_.size(), std::max(k, candidates_),
            [&](std::size_t j) { return RingKeyDistanceSq(q.ring_key, store_.RingKeyOf(j)); },
            [&](std::size_t j) { return indexed_[j] != 0 && (!eligible || eligible(j)); });
        for (Neighbor& n : found) n.distance = store_.Distance(query, n.index);
        std::sort(found.begin(), found.end(), [](const Neighbor& a, const Neighbor& b) {
            return a.distance < b.distance || (a.distance == b.distance && a.index < b.index);
        });
        if (found.size() > k) found.resize(k);
        return found;
    }
    bool IsExact() const override { return false; }

private:
    const ScanContextStore& store_;
    std::size_t candidates_;
    std::vector<std::uint8_t> indexed_;
};

std::unique_ptr<NeighborIndex> ScanContextStore::MakeIndex() const {
    if (config_.ring_key_candidates == 0) return nullptr;  // compare every eligible scan
    return std::make_unique<RingKeyIndex>(*this,
                                          static_cast<std::size_t>(config_.ring_key_candidates));
}

}  // namespace

core::Descriptor ScanContextMethod::Describe(const core::PointCloud& cloud,
                                             const core::DescriptorConfig& config) const {
    return DescribeView(cloud, config);
}

core::Descriptor ScanContextMethod::DescribeView(core::PointsView points,
                                                 const core::DescriptorConfig& config) const {
    return {method(), core::ComputeScanContext(points, ConfigOf(config))};
}

double ScanContextMethod::Distance(const core::Descriptor& a, const core::Descriptor& b) const {
    return MatchScanContexts(a, b).distance;
}

std::unique_ptr<DescriptorStore> ScanContextMethod::MakeStore(
    const core::DescriptorConfig& config) const {
    return std::make_unique<ScanContextStore>(ConfigOf(config));
}

std::optional<core::MethodParameters> ScanContextMethod::DefaultParameters() const {
    return core::MethodParameters(name(), core::ScanContextConfig{});
}

const core::ScanContextConfig& ScanContextMethod::ConfigOf(const core::DescriptorConfig& config) {
    return config.methods.Get<core::ScanContextConfig>(kMethod.name());
}

void ScanContextMethod::ValidateThreshold(double threshold) const {
    if (!(threshold >= 0.0 && threshold <= 1.0)) {
        throw core::ConfigError(
            "detection.threshold must be in [0, 1] for scancontext (the range of its "
            "distance), got " +
            core::NumberText(threshold));
    }
}

core::ScanContextMatch MatchScanContexts(const core::Descriptor& query,
                                         const core::Descriptor& candidate) {
    return core::CompareScanContexts(query.As<ScanContext>(), candidate.As<ScanContext>());
}

}  // namespace lidarloop::pipeline

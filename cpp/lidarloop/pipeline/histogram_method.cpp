#include "lidarloop/pipeline/histogram_method.hpp"

#include <cmath>
#include <string>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/core/wasserstein.hpp"
#include "lidarloop/pipeline/histogram_index.hpp"

namespace lidarloop::pipeline {
namespace {

struct HistogramQuery : PreparedQuery {
    std::vector<float> row;  // padded cumulative histogram
};

const HistogramQuery& RowOf(const PreparedQuery& query) {
    return static_cast<const HistogramQuery&>(query);
}

class HistogramNeighborIndex : public NeighborIndex {
public:
    explicit HistogramNeighborIndex(const CumulativeHistograms& rows) : index_(rows) {}
    void Insert(std::size_t id) override { index_.Insert(id); }
    void InsertAll(const std::function<bool(std::size_t)>& include) override {
        index_.InsertAll(include);
    }
    std::vector<Neighbor> Search(const PreparedQuery& query, std::size_t k,
                                 const std::function<bool(std::size_t)>& eligible) const override {
        return index_.Search(RowOf(query).row.data(), k, eligible);
    }

private:
    HistogramIndex index_;
};

class HistogramStore : public DescriptorStore {
public:
    explicit HistogramStore(int bins) : rows_(bins) {}
    const CumulativeHistograms& rows() const { return rows_; }

    std::unique_ptr<DescriptorStore> Clone() const override {
        return std::make_unique<HistogramStore>(*this);
    }
    void Add(const core::Descriptor& descriptor) override {
        rows_.Add(descriptor.histogram().mass);
    }
    void AddMissing() override {
        rows_.AddRow(std::vector<float>(static_cast<std::size_t>(rows_.stride())));
    }
    double Distance(std::size_t i, std::size_t j) const override { return rows_.Distance(i, j); }
    std::unique_ptr<PreparedQuery> Prepare(const core::Descriptor& descriptor) const override {
        auto query = std::make_unique<HistogramQuery>();
        query->row = rows_.MakeRow(descriptor.histogram().mass);
        return query;
    }
    std::unique_ptr<PreparedQuery> PrepareStored(std::size_t i) const override {
        auto query = std::make_unique<HistogramQuery>();
        query->row.assign(rows_.Row(i), rows_.Row(i) + rows_.stride());
        return query;
    }
    double Distance(const PreparedQuery& query, std::size_t j) const override {
        return rows_.DistanceToRow(RowOf(query).row.data(), j);
    }
    std::unique_ptr<NeighborIndex> MakeIndex() const override {
        return std::make_unique<HistogramNeighborIndex>(rows_);
    }
    // The row as stored, placeholders included: stride floats.
    void Encode(std::size_t i, core::ByteWriter& out) const override {
        out.PutArray(rows_.Row(i), static_cast<std::size_t>(rows_.stride()));
    }
    void Decode(core::ByteReader& in, bool valid) override {
        std::vector<float> row(static_cast<std::size_t>(rows_.stride()));
        in.GetArray(row.data(), row.size(), "cumulative histogram");
        if (const std::string problem = RowProblem(row, valid); !problem.empty()) in.Fail(problem);
        rows_.AddRow(row);
    }

private:
    // What makes a stored row something MakeRow cannot have written ("" if nothing): a cumulative
    // mass rises from 0 to 1 (a placeholder is all 0), and the padding after the bins is 0.
    std::string RowProblem(const std::vector<float>& row, bool valid) const {
        const auto bins = static_cast<std::size_t>(rows_.bins());
        float previous = 0.0f;
        for (std::size_t k = 0; k < bins; ++k) {
            if (!(row[k] >= previous && row[k] <= 1.0f + kMassTolerance))
                return "cumulative histogram is not a rising share in [0, 1] at bucket " +
                       std::to_string(k);
            previous = row[k];
        }
        if (valid && !(std::abs(previous - 1.0f) <= kMassTolerance))
            return "cumulative histogram does not end at 1";
        for (std::size_t k = bins; k < row.size(); ++k) {
            if (row[k] != 0.0f) return "cumulative histogram has values beyond its buckets";
        }
        return {};
    }

    // A float sum of up to a million shares that add up to 1 in double.
    static constexpr float kMassTolerance = 1e-3f;
    CumulativeHistograms rows_;
};

}  // namespace

HistogramMethod::HistogramMethod(core::Method method) : DescriptorMethod(method) {
    core::ProjectionOf(method);  // ConfigError for a method that is not a projection
}

core::Descriptor HistogramMethod::Describe(const core::PointCloud& cloud,
                                           const core::DescriptorConfig& config) const {
    return DescribeView(cloud, config);
}

core::Descriptor HistogramMethod::DescribeView(core::PointsView points,
                                               const core::DescriptorConfig& config) const {
    return {method(),
            core::ComputeHistogram(points, core::ProjectionOf(method()), config.histogram)};
}

double HistogramMethod::Distance(const core::Descriptor& a, const core::Descriptor& b) const {
    return core::WassersteinDistance(a.histogram().mass, b.histogram().mass);
}

std::unique_ptr<DescriptorStore> HistogramMethod::MakeStore(
    const core::DescriptorConfig& config) const {
    return std::make_unique<HistogramStore>(config.histogram.bins);
}

bool HistogramMethod::IsMatch(double distance, double threshold) const {
    return core::IsLoop(distance, threshold);
}

void HistogramMethod::ValidateThreshold(double threshold) const {
    if (!(threshold >= 0.0 && threshold <= 1.0)) {
        throw core::ConfigError("detection.threshold must be in [0, 1] for " + name() +
                                " (the range of W), got " + core::NumberText(threshold));
    }
}

const CumulativeHistograms* HistogramRows(const DescriptorDatabase& database) {
    const auto* store = dynamic_cast<const HistogramStore*>(&database.store());
    return store != nullptr ? &store->rows() : nullptr;
}

}  // namespace lidarloop::pipeline

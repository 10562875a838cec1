#include "lidarloop/pipeline/ndt_method.hpp"

#include <cmath>
#include <optional>
#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::pipeline {
namespace {

constexpr std::uint32_t kMaxMatrixEntries = 1u << 24;

void PutNdtSet(core::ByteWriter& out, const core::NdtDescriptorSet& set) {
    out.Put<std::uint32_t>(static_cast<std::uint32_t>(set.descriptors.size()));
    for (const core::NdtDescriptor& f : set.descriptors) {
        out.Put<std::uint32_t>(static_cast<std::uint32_t>(f.rows));
        out.Put<std::uint32_t>(static_cast<std::uint32_t>(f.cols));
        out.Put<double>(f.total);
        out.PutArray(f.counts.data(), f.counts.size());
        out.PutArray(f.R_aligned_sensor.data(), 9);
    }
}

// Finite, orthonormal and right-handed, to the precision a stored rotation keeps.
template <typename Matrix>
bool IsRotation(const Matrix& R) {
    constexpr double kTolerance = 1e-4;
    return R.allFinite() &&
           (R.transpose() * R - Matrix::Identity()).cwiseAbs().maxCoeff() <= kTolerance &&
           std::abs(R.determinant() - 1.0) <= kTolerance;
}

core::NdtDescriptorSet GetNdtSet(core::ByteReader& in) {
    core::NdtDescriptorSet set;
    const auto count = in.Get<std::uint32_t>("NDT descriptor count");
    in.RequireItems(count, 16, "NDT descriptors");
    for (std::uint32_t d = 0; d < count; ++d) {
        const auto rows = in.Get<std::uint32_t>("NDT rows");
        const auto cols = in.Get<std::uint32_t>("NDT columns");
        const std::uint64_t entries = std::uint64_t{rows} * cols;
        if (entries > kMaxMatrixEntries) in.Fail("absurd NDT descriptor size");
        const auto stored_total = in.Get<double>("NDT cell total");
        std::vector<float> counts(entries);
        in.GetArray(counts.data(), counts.size(), "NDT counts");
        core::NdtDescriptor f;
        in.GetArray(f.R_aligned_sensor.data(), 9, "NDT rotation");
        if (!IsRotation(f.R_aligned_sensor)) in.Fail("NDT rotation is not a rotation matrix");
        try {
            core::SetNdtCounts(f, static_cast<int>(rows), static_cast<int>(cols),
                               std::move(counts));
        } catch (const core::ConfigError& error) {
            in.Fail(error.what());
        }
        // Counts are whole numbers, so their sum is exact: any difference is a damaged file.
        if (!(std::abs(f.total - stored_total) < 0.5))
            in.Fail("NDT cell total differs from its counts");
        set.descriptors.push_back(std::move(f));
    }
    return set;
}

struct NdtQuery : PreparedQuery {
    core::NdtDescriptorSet set;
};

class NdtStore : public DescriptorStore {
    // Every descriptor of the store has one shape (range intervals x features): one of another
    // config would make every later distance fail, so it is refused where it comes in. The
    // mismatch found, if any.
    std::optional<std::string> ShapeMismatch(const core::NdtDescriptorSet& set) const {
        const core::NdtDescriptor* reference =
            set.descriptors.empty() ? nullptr : &set.descriptors.front();
        for (const core::NdtDescriptorSet& s : sets_) {
            if (!s.descriptors.empty()) {
                reference = &s.descriptors.front();
                break;
            }
        }
        for (const core::NdtDescriptor& f : set.descriptors) {
            if (f.rows != reference->rows || f.cols != reference->cols) {
                return "an NDT descriptor of " + std::to_string(f.rows) + " x " +
                       std::to_string(f.cols) + " beside ones of " +
                       std::to_string(reference->rows) + " x " + std::to_string(reference->cols) +
                       " (range intervals x features)";
            }
        }
        return std::nullopt;
    }

public:
    const std::vector<core::NdtDescriptorSet>& sets() const { return sets_; }

    std::unique_ptr<DescriptorStore> Clone() const override {
        return std::make_unique<NdtStore>(*this);
    }
    void Add(const core::Descriptor& descriptor) override {
        if (const auto mismatch = ShapeMismatch(descriptor.ndt()))
            throw core::ConfigError(*mismatch + ": describe it with the database's config");
        sets_.push_back(descriptor.ndt());
    }
    void AddMissing() override { sets_.emplace_back(); }
    double Distance(std::size_t i, std::size_t j) const override {
        return core::NdtSetDifference(sets_[i], sets_[j]);
    }
    std::unique_ptr<PreparedQuery> Prepare(const core::Descriptor& descriptor) const override {
        auto query = std::make_unique<NdtQuery>();
        query->set = descriptor.ndt();
        return query;
    }
    std::unique_ptr<PreparedQuery> PrepareStored(std::size_t i) const override {
        auto query = std::make_unique<NdtQuery>();
        query->set = sets_[i];
        return query;
    }
    double Distance(const PreparedQuery& query, std::size_t j) const override {
        return core::NdtSetDifference(static_cast<const NdtQuery&>(query).set, sets_[j]);
    }
    // Rotation candidates (section II-C, one descriptor each) and classified cells per scan, so
    // that a time per scan can be read against what it covered.
    std::vector<WorkFigure> Work(const std::vector<std::uint8_t>& valid) const override {
        WorkFigure candidates{"rotation_candidates_per_scan", {}};
        WorkFigure cells{"classified_cells_per_scan", {}};
        for (std::size_t i = 0; i < sets_.size(); ++i) {
            if (!valid[i]) continue;
            const auto& descriptors = sets_[i].descriptors;
            candidates.values.push_back(static_cast<double>(descriptors.size()));
            cells.values.push_back(descriptors.empty() ? 0.0 : descriptors.front().total);
        }
        return {candidates, cells};
    }
    void Encode(std::size_t i, core::ByteWriter& out) const override { PutNdtSet(out, sets_[i]); }
    void Decode(core::ByteReader& in, bool /*valid*/) override {
        core::NdtDescriptorSet set = GetNdtSet(in);
        if (const auto mismatch = ShapeMismatch(set)) in.Fail(*mismatch);
        sets_.push_back(std::move(set));
    }

private:
    std::vector<core::NdtDescriptorSet> sets_;
};

}  // namespace

core::Descriptor NdtMethod::Describe(const core::PointCloud& cloud,
                                     const core::DescriptorConfig& config) const {
    return {method(), core::ComputeNdtDescriptorSet(cloud, config.ndt)};
}

double NdtMethod::Distance(const core::Descriptor& a, const core::Descriptor& b) const {
    return core::NdtSetDifference(a.ndt(), b.ndt());
}

std::unique_ptr<DescriptorStore> NdtMethod::MakeStore(const core::DescriptorConfig&) const {
    return std::make_unique<NdtStore>();
}

const std::vector<core::NdtDescriptorSet>* NdtSets(const DescriptorDatabase& database) {
    const auto* store = dynamic_cast<const NdtStore*>(&database.store());
    return store != nullptr ? &store->sets() : nullptr;
}

}  // namespace lidarloop::pipeline

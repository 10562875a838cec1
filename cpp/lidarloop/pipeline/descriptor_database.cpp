#include "lidarloop/pipeline/descriptor_database.hpp"

#include <limits>

#include "lidarloop/core/error.hpp"

namespace lidarloop::pipeline {

namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();
}  // namespace

DescriptorDatabase::DescriptorDatabase(const core::DescriptorConfig& config) : config_(config) {
    config_.Validate();
    if (core::IsHistogramMethod(config_.method)) histograms_.emplace(config_.histogram.bins);
}

void DescriptorDatabase::CheckMethod(const core::Descriptor& descriptor) const {
    if (descriptor.method != config_.method) {
        throw core::ConfigError("a " + core::ToString(descriptor.method) +
                                " descriptor cannot join a " + core::ToString(config_.method) +
                                " database");
    }
}

std::size_t DescriptorDatabase::Add(const core::Descriptor& descriptor, double time_s) {
    CheckMethod(descriptor);
    if (histograms_) return AddCumulativeRow(Prepare(descriptor).cumulative_row, time_s, true);
    return AddNdtSet(descriptor.ndt(), time_s, true);
}

std::size_t DescriptorDatabase::AddMissing(double time_s) {
    if (histograms_) {
        return AddCumulativeRow(std::vector<float>(static_cast<std::size_t>(histograms_->stride())),
                                time_s, false);
    }
    return AddNdtSet({}, time_s, false);
}

std::size_t DescriptorDatabase::AddCumulativeRow(std::span<const float> row, double time_s,
                                                 bool valid) {
    if (!histograms_) throw core::ConfigError("an NDT database holds no histogram rows");
    histograms_->AddRow(row);
    times_s_.push_back(time_s);
    valid_.push_back(valid ? 1 : 0);
    return size() - 1;
}

std::size_t DescriptorDatabase::AddNdtSet(core::NdtDescriptorSet set, double time_s, bool valid) {
    if (histograms_) throw core::ConfigError("a histogram database holds no NDT sets");
    ndt_sets_.push_back(std::move(set));
    times_s_.push_back(time_s);
    valid_.push_back(valid ? 1 : 0);
    return size() - 1;
}

double DescriptorDatabase::Distance(std::size_t i, std::size_t j) const {
    if (!IsValid(i) || !IsValid(j)) return kInfinity;
    if (histograms_) return histograms_->Distance(i, j);
    return core::NdtSetDifference(ndt_sets_[i], ndt_sets_[j]);
}

PreparedQuery DescriptorDatabase::Prepare(const core::Descriptor& descriptor) const {
    CheckMethod(descriptor);
    PreparedQuery query;
    if (histograms_) {
        query.cumulative_row = histograms_->MakeRow(descriptor.histogram().mass);
    } else {
        query.ndt = descriptor.ndt();
    }
    return query;
}

PreparedQuery DescriptorDatabase::PrepareStored(std::size_t i) const {
    if (i >= size() || !IsValid(i)) {
        throw core::ConfigError("scan " + std::to_string(i) + " of the database is " +
                                (i >= size() ? "not stored" : "missing (it could not be read)"));
    }
    PreparedQuery query;
    if (histograms_) {
        const float* row = histograms_->Row(i);
        query.cumulative_row.assign(row, row + histograms_->stride());
    } else {
        query.ndt = ndt_sets_[i];
    }
    return query;
}

double DescriptorDatabase::Distance(const PreparedQuery& query, std::size_t j) const {
    if (!IsValid(j)) return kInfinity;
    if (histograms_) return histograms_->DistanceToRow(query.cumulative_row.data(), j);
    return core::NdtSetDifference(query.ndt, ndt_sets_[j]);
}

}  // namespace lidarloop::pipeline

#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/pipeline/cumulative_histograms.hpp"

namespace lidarloop::pipeline {

/// A descriptor prepared for many comparisons against a database.
struct PreparedQuery {
    std::vector<float> cumulative_row;  ///< histogram methods: padded cumulative histogram
    core::NdtDescriptorSet ndt;         ///< NDT: the descriptor set
};

/// The descriptors of a sequence of scans, one method, in scan order. A scan that could not be
/// read has a placeholder entry that matches nothing (distance +inf). Histograms are stored as
/// cumulative float rows (CumulativeHistograms); NDT descriptor sets as computed.
/// Not thread-safe for writing; concurrent reads are safe.
class DescriptorDatabase {
public:
    /// Validates `config` (ConfigError).
    explicit DescriptorDatabase(const core::DescriptorConfig& config);

    const core::DescriptorConfig& config() const { return config_; }
    core::Method method() const { return config_.method; }
    std::size_t size() const { return times_s_.size(); }

    /// Appends the descriptor of the next scan; its method must be the database's.
    std::size_t Add(const core::Descriptor& descriptor, double time_s);
    /// Appends a placeholder for a scan that could not be described.
    std::size_t AddMissing(double time_s);

    bool IsValid(std::size_t i) const { return valid_[i] != 0; }
    double TimeS(std::size_t i) const { return times_s_[i]; }
    const std::vector<double>& times_s() const { return times_s_; }

    /// Distance between stored scans: W (histograms) or sigma' (NDT); +inf if one is missing.
    double Distance(std::size_t i, std::size_t j) const;

    PreparedQuery Prepare(const core::Descriptor& descriptor) const;
    /// Stored scan i as a query (to search another database with it); it must be valid.
    PreparedQuery PrepareStored(std::size_t i) const;
    /// Distance between a prepared query and stored scan j; +inf if j is missing.
    double Distance(const PreparedQuery& query, std::size_t j) const;

    /// The histogram rows (nullptr for NDT).
    const CumulativeHistograms* histograms() const { return histograms_ ? &*histograms_ : nullptr; }
    /// The NDT sets (empty for histogram methods).
    const std::vector<core::NdtDescriptorSet>& ndt_sets() const { return ndt_sets_; }

    /// Appends a raw cumulative row (histogram methods; used when loading a saved database).
    std::size_t AddCumulativeRow(std::span<const float> row, double time_s, bool valid);
    /// Appends an NDT set (used when loading a saved database).
    std::size_t AddNdtSet(core::NdtDescriptorSet set, double time_s, bool valid);

private:
    void CheckMethod(const core::Descriptor& descriptor) const;

    core::DescriptorConfig config_;
    std::optional<CumulativeHistograms> histograms_;
    std::vector<core::NdtDescriptorSet> ndt_sets_;
    std::vector<double> times_s_;
    std::vector<std::uint8_t> valid_;
};

}  // namespace lidarloop::pipeline

#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "lidarloop/core/byte_codec.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::pipeline {

/// The descriptors of a sequence of scans, one method, in scan order, with their times. A scan
/// that could not be read has a placeholder entry that matches nothing (distance +inf). The
/// method's DescriptorStore keeps them in the form that compares fastest.
/// Not thread-safe for writing; concurrent reads are safe.
class DescriptorDatabase {
public:
    /// Validates `config` (ConfigError), including that its method is registered.
    explicit DescriptorDatabase(const core::DescriptorConfig& config);
    DescriptorDatabase(const DescriptorDatabase& other);
    DescriptorDatabase& operator=(const DescriptorDatabase& other);
    DescriptorDatabase(DescriptorDatabase&&) noexcept = default;
    DescriptorDatabase& operator=(DescriptorDatabase&&) noexcept = default;

    const core::DescriptorConfig& config() const { return config_; }
    const core::Method& method() const { return config_.method; }
    /// The method the descriptors belong to.
    const DescriptorMethod& definition() const { return *definition_; }
    std::size_t size() const { return times_s_.size(); }

    /// Appends the descriptor of the next scan; its method must be the database's and its time
    /// finite (else core::ConfigError, nothing stored).
    std::size_t Add(const core::Descriptor& descriptor, double time_s);
    /// Appends a placeholder for a scan that could not be described (time as for Add).
    std::size_t AddMissing(double time_s);
    /// core::ConfigError naming the next scan unless `time_s` is finite: what Add and AddMissing
    /// check before storing anything.
    void CheckTime(double time_s) const;

    bool IsValid(std::size_t i) const { return valid_[i] != 0; }
    double TimeS(std::size_t i) const { return times_s_[i]; }
    const std::vector<double>& times_s() const { return times_s_; }

    /// The method's distance between stored scans; +inf if one is missing.
    double Distance(std::size_t i, std::size_t j) const;

    std::unique_ptr<PreparedQuery> Prepare(const core::Descriptor& descriptor) const;
    /// Stored scan i as a query (to search another database with it); it must be valid.
    std::unique_ptr<PreparedQuery> PrepareStored(std::size_t i) const;
    /// Distance between a prepared query and stored scan j; +inf if j is missing.
    double Distance(const PreparedQuery& query, std::size_t j) const;

    const DescriptorStore& store() const { return *store_; }
    /// Per-scan work figures of the valid scans (e.g. NDT rotation candidates).
    std::vector<WorkFigure> Work() const { return store_->Work(valid_); }

    /// Writes scan i (time, valid flag, the store's encoding) for a saved database.
    void Encode(std::size_t i, core::ByteWriter& out) const;
    /// Appends a scan written by Encode; calls in.Fail for damaged data.
    std::size_t Decode(core::ByteReader& in);

private:
    void CheckMethod(const core::Descriptor& descriptor) const;
    std::size_t Append(double time_s, bool valid);

    core::DescriptorConfig config_;
    const DescriptorMethod* definition_;
    std::unique_ptr<DescriptorStore> store_;
    std::vector<double> times_s_;
    std::vector<std::uint8_t> valid_;
};

}  // namespace lidarloop::pipeline

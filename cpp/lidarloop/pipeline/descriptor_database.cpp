#include "lidarloop/pipeline/descriptor_database.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"

namespace lidarloop::pipeline {

namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();
}  // namespace

DescriptorDatabase::DescriptorDatabase(const core::DescriptorConfig& config)
    : config_(config), definition_(&MethodOf(config.method)) {
    config_.Validate();
    store_ = definition_->MakeStore(config_);
}

DescriptorDatabase::DescriptorDatabase(const DescriptorDatabase& other)
    : config_(other.config_),
      definition_(other.definition_),
      store_(other.store_->Clone()),
      times_s_(other.times_s_),
      valid_(other.valid_) {}

DescriptorDatabase& DescriptorDatabase::operator=(const DescriptorDatabase& other) {
    if (this != &other) *this = DescriptorDatabase(other);
    return *this;
}

void DescriptorDatabase::CheckMethod(const core::Descriptor& descriptor) const {
    if (!(descriptor.method == config_.method)) {
        throw core::ConfigError("a " + core::ToString(descriptor.method) +
                                " descriptor cannot join a " + core::ToString(config_.method) +
                                " database");
    }
}

// A NaN time would make every gap in seconds false.
void DescriptorDatabase::CheckTime(double time_s) const {
    if (!std::isfinite(time_s)) {
        throw core::ConfigError("scan " + std::to_string(size()) + ": time " +
                                core::NumberText(time_s) + " s is not finite");
    }
}

std::size_t DescriptorDatabase::Append(double time_s, bool valid) {
    times_s_.push_back(time_s);
    valid_.push_back(valid ? 1 : 0);
    return size() - 1;
}

std::size_t DescriptorDatabase::Add(const core::Descriptor& descriptor, double time_s) {
    CheckMethod(descriptor);
    CheckTime(time_s);
    store_->Add(descriptor);
    return Append(time_s, true);
}

std::size_t DescriptorDatabase::AddMissing(double time_s) {
    CheckTime(time_s);
    store_->AddMissing();
    return Append(time_s, false);
}

double DescriptorDatabase::Distance(std::size_t i, std::size_t j) const {
    if (!IsValid(i) || !IsValid(j)) return kInfinity;
    return store_->Distance(i, j);
}

std::unique_ptr<PreparedQuery> DescriptorDatabase::Prepare(
    const core::Descriptor& descriptor) const {
    CheckMethod(descriptor);
    return store_->Prepare(descriptor);
}

std::unique_ptr<PreparedQuery> DescriptorDatabase::PrepareStored(std::size_t i) const {
    if (i >= size() || !IsValid(i)) {
        throw core::ConfigError("scan " + std::to_string(i) + " of the database is " +
                                (i >= size() ? "not stored" : "missing (it could not be read)"));
    }
    return store_->PrepareStored(i);
}

double DescriptorDatabase::Distance(const PreparedQuery& query, std::size_t j) const {
    if (!IsValid(j)) return kInfinity;
    return store_->Distance(query, j);
}

void DescriptorDatabase::Encode(std::size_t i, core::ByteWriter& out) const {
    out.Put<double>(TimeS(i));
    out.Put<std::uint8_t>(valid_[i]);
    store_->Encode(i, out);
}

std::size_t DescriptorDatabase::Decode(core::ByteReader& in) {
    const auto time_s = in.Get<double>("scan time");
    if (!std::isfinite(time_s)) in.Fail("scan time is not finite");
    const auto flag = in.Get<std::uint8_t>("valid flag");
    if (flag > 1) in.Fail("valid flag is neither 0 nor 1");
    const bool valid = flag == 1;
    store_->Decode(in, valid);
    return Append(time_s, valid);
}

}  // namespace lidarloop::pipeline

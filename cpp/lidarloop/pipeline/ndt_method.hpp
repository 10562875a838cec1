#pragma once

#include <memory>
#include <vector>

#include "lidarloop/core/ndt/ndt_descriptor.hpp"
#include "lidarloop/pipeline/descriptor_database.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::pipeline {

/// Magnusson et al. 2009 as a DescriptorMethod: the NDT appearance descriptors of a scan, one per
/// rotation candidate (core::ComputeNdtDescriptorSet), compared by sigma' (eq. 9), similar when
/// sigma' < t_d (section II-E). Stored as computed; compared with every eligible scan.
class NdtMethod : public DescriptorMethod {
public:
    NdtMethod() : DescriptorMethod(core::Method::kNdt) {}

    core::Descriptor Describe(const core::PointCloud& cloud,
                              const core::DescriptorConfig& config) const override;
    double Distance(const core::Descriptor& a, const core::Descriptor& b) const override;
    std::unique_ptr<DescriptorStore> MakeStore(const core::DescriptorConfig& config) const override;
    /// t_d = 0.0737: Magnusson table II, Hannover2. It depends on the data; estimate it (EM) or
    /// learn it for yours.
    double DefaultThreshold() const override { return 0.0737; }
    /// sigma' < t_d: the paper's strict comparison.
    bool IsMatch(double distance, double threshold) const override { return distance < threshold; }
};

/// The descriptor sets of an NDT database (one per scan, placeholders empty); nullptr for a
/// database of another method.
const std::vector<core::NdtDescriptorSet>* NdtSets(const DescriptorDatabase& database);

}  // namespace lidarloop::pipeline

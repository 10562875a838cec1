#pragma once

#include <memory>

#include "lidarloop/core/scancontext/scancontext.hpp"
#include "lidarloop/core/scancontext/scancontext_distance.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::pipeline {

/// Kim & Kim 2018 (Scan Context, IROS) as a DescriptorMethod, named "scancontext": the polar
/// max-height matrix of a scan (core::ComputeScanContext), compared by the column-shift distance
/// (core::CompareScanContexts, eq. 5-6), a loop when the distance <= the threshold. Stored as
/// unit columns; with scancontext.ring_key_candidates > 0 searched through the ring key first
/// (eq. 6-7; an approximate index), else by comparing every eligible scan.
class ScanContextMethod : public DescriptorMethod {
public:
    static constexpr core::Method kMethod{"scancontext"};

    ScanContextMethod() : DescriptorMethod(kMethod) {}

    core::Descriptor Describe(const core::PointCloud& cloud,
                              const core::DescriptorConfig& config) const override;
    /// No copy: the binning reads the view.
    core::Descriptor DescribeView(core::PointsView points,
                                  const core::DescriptorConfig& config) const override;
    double Distance(const core::Descriptor& a, const core::Descriptor& b) const override;
    std::unique_ptr<DescriptorStore> MakeStore(const core::DescriptorConfig& config) const override;
    /// core::ScanContextConfig under the section `scancontext`.
    std::optional<core::MethodParameters> DefaultParameters() const override;
    /// The parameters `config` holds for this method, or the defaults.
    static const core::ScanContextConfig& ConfigOf(const core::DescriptorConfig& config);
    /// 0.13: the acceptance distance of the authors' implementation (0.1-0.2 across their
    /// papers). It depends on the sensor and the scene; learn yours.
    double DefaultThreshold() const override { return 0.13; }
    /// The distance is in [0, 1].
    void ValidateThreshold(double threshold) const override;
};

/// The full match (distance, shift, yaw) of two Scan Context descriptors (ConfigError for a
/// descriptor of another type).
core::ScanContextMatch MatchScanContexts(const core::Descriptor& query,
                                         const core::Descriptor& candidate);

}  // namespace lidarloop::pipeline

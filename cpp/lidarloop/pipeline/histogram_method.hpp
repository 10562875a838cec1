#pragma once

#include <memory>
#include <span>
#include <vector>

#include "lidarloop/pipeline/cumulative_histograms.hpp"
#include "lidarloop/pipeline/descriptor_database.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::pipeline {

/// Röhling et al. 2015 as a DescriptorMethod: the height or range histogram of a scan
/// (core::ComputeHistogram), compared by the Wasserstein distance W (eq. 6), a loop when
/// W <= tau (eq. 7). Stored as cumulative float rows (CumulativeHistograms) and searched
/// through the exact HistogramIndex.
class HistogramMethod : public DescriptorMethod {
public:
    /// `method` is core::Method::kHeight or kRange (ConfigError otherwise).
    explicit HistogramMethod(core::Method method);

    core::Descriptor Describe(const core::PointCloud& cloud,
                              const core::DescriptorConfig& config) const override;
    /// No copy: the histogram reads the view.
    core::Descriptor DescribeView(core::PointsView points,
                                  const core::DescriptorConfig& config) const override;
    double Distance(const core::Descriptor& a, const core::Descriptor& b) const override;
    std::unique_ptr<DescriptorStore> MakeStore(const core::DescriptorConfig& config) const override;
    /// tau = 0.005: Röhling table II, MCC is best near 0.005 on every route. Their b and value
    /// range are not published, so treat it as a starting point and learn yours.
    double DefaultThreshold() const override { return 0.005; }
    /// W <= tau (Röhling eq. 7, core::IsLoop).
    bool IsMatch(double distance, double threshold) const override;
    /// tau in [0, 1], the range of W.
    void ValidateThreshold(double threshold) const override;
};

/// The cumulative rows of a histogram database (one per scan, placeholders all zero); nullptr
/// for a database of another method.
const CumulativeHistograms* HistogramRows(const DescriptorDatabase& database);

}  // namespace lidarloop::pipeline

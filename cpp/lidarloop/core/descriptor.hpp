#pragma once

#include <variant>

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/histogram.hpp"
#include "lidarloop/core/ndt_descriptor.hpp"
#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::core {

/// The place descriptor of one scan under any method: what detection, evaluation and benchmarks
/// handle without knowing which paper it comes from.
struct Descriptor {
    Method method = Method::kHeight;
    std::variant<Histogram, NdtDescriptorSet> value;

    const Histogram& histogram() const { return std::get<Histogram>(value); }
    const NdtDescriptorSet& ndt() const { return std::get<NdtDescriptorSet>(value); }
};

/// Computes the descriptor `config.method` names. Throws EmptyInputError for a scan with nothing
/// usable, ConfigError for an invalid config. Thread-safe.
Descriptor ComputeDescriptor(const PointCloud& cloud, const DescriptorConfig& config);

/// Distance between two descriptors of the same method: Röhling's W (eq. 6) for histograms,
/// Magnusson's sigma' (eq. 9) for NDT. Smaller is more similar. ConfigError on mixed methods.
double DescriptorDistance(const Descriptor& a, const Descriptor& b);

/// The method's default decision threshold, the one place it is written: tau = 0.005 for the
/// histograms (Röhling table II: MCC is best near 0.005 on every route; their b and value range
/// are not published, so treat it as a starting point) and t_d = 0.0737 for NDT (Magnusson table
/// II, Hannover2). Both depend on the data: learn yours with `lidarloop evaluate`.
double DefaultThreshold(Method method);

/// Whether `distance` says "same place" under `threshold`, with each paper's own comparison:
/// W <= tau (Röhling eq. 7), sigma' < t_d (Magnusson II-E, table I).
bool IsMatch(Method method, double distance, double threshold);

}  // namespace lidarloop::core

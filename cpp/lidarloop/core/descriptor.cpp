#include "lidarloop/core/descriptor.hpp"

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/wasserstein.hpp"

namespace lidarloop::core {

Descriptor ComputeDescriptor(const PointCloud& cloud, const DescriptorConfig& config) {
    if (config.method == Method::kNdt) {
        return {config.method, ComputeNdtDescriptorSet(cloud, config.ndt)};
    }
    return {config.method, ComputeHistogram(cloud, ProjectionOf(config.method), config.histogram)};
}

double DescriptorDistance(const Descriptor& a, const Descriptor& b) {
    if (a.method != b.method) {
        throw ConfigError("cannot compare a " + ToString(a.method) + " descriptor with a " +
                          ToString(b.method) + " descriptor");
    }
    if (a.method == Method::kNdt) return NdtSetDifference(a.ndt(), b.ndt());
    return WassersteinDistance(a.histogram().mass, b.histogram().mass);
}

double DefaultThreshold(Method method) { return method == Method::kNdt ? 0.0737 : 0.005; }

bool IsMatch(Method method, double distance, double threshold) {
    return method == Method::kNdt ? distance < threshold : IsLoop(distance, threshold);
}

}  // namespace lidarloop::core

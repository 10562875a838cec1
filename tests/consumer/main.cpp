// Uses the installed headers and libraries: a histogram and a distance from two tiny scans.
#include <cstdio>

#include "lidarloop/core/histogram.hpp"
#include "lidarloop/core/wasserstein.hpp"
#include "lidarloop/io/config_yaml.hpp"

int main() {
    const lidarloop::io::RunConfig config;
    const lidarloop::core::PointCloud a = {{1, 0, -1.5f}, {0, 2, 0.5f}, {3, 3, 2.0f}};
    const lidarloop::core::PointCloud b = {{1, 0, -1.5f}, {0, 2, 0.5f}, {3, 3, 2.5f}};
    const auto& histogram_config = config.descriptor.histogram;
    const auto ha = ComputeHistogram(a, lidarloop::core::Projection::kHeight, histogram_config);
    const auto hb = ComputeHistogram(b, lidarloop::core::Projection::kHeight, histogram_config);
    const double w = lidarloop::core::WassersteinDistance(ha.mass, hb.mass);
    std::printf("consumer: W = %g\n", w);
    return (w > 0.0 && w < 1.0) ? 0 : 1;
}

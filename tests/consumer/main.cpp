// Uses the installed headers and libraries: two tiny scans described through the method
// registry, their distance, and the run layer's JSON form of a descriptor.
#include <cstdio>

#include "lidarloop/lidarloop.hpp"  // the one header for library users

int main() {
    namespace ll = lidarloop;
    const ll::io::RunConfig config;
    const ll::core::PointCloud a = {{1, 0, -1.5f}, {0, 2, 0.5f}, {3, 3, 2.0f}};
    const ll::core::PointCloud b = {{1, 0, -1.5f}, {0, 2, 0.5f}, {3, 3, 2.5f}};
    const auto da = ll::pipeline::ComputeDescriptor(a, config.descriptor);
    const auto db = ll::pipeline::ComputeDescriptor(b, config.descriptor);
    const double w = ll::pipeline::DescriptorDistance(da, db);
    const auto json = ll::app::DescriptorJson(da);
    std::printf("consumer: W = %g, %s descriptor of %zu points\n", w,
                json["method"].get<std::string>().c_str(), json["points_used"].get<std::size_t>());
    return (w > 0.0 && w < 1.0 && json["points_used"] == 3) ? 0 : 1;
}

// Describes two scans with one method and says whether they show the same place.
// Usage: describe_and_compare SCAN_A SCAN_B [height|range|ndt]
#include <cstdio>
#include <exception>

#include "lidarloop/io/scan_reader.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace ll = lidarloop;

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s SCAN_A SCAN_B [height|range|ndt]\n", argv[0]);
        return 2;
    }
    try {
        ll::core::DescriptorConfig config;  // the defaults of docs/histograms.md and docs/ndt.md
        if (argc > 3) config.method = ll::pipeline::ParseMethod(argv[3]);
        const ll::core::Descriptor a =
            ll::pipeline::ComputeDescriptor(ll::io::ReadScan(argv[1]), config);
        const ll::core::Descriptor b =
            ll::pipeline::ComputeDescriptor(ll::io::ReadScan(argv[2]), config);
        const double distance = ll::pipeline::DescriptorDistance(a, b);
        const double threshold = ll::pipeline::DefaultThreshold(config.method);
        std::printf("%s distance %.6g: %s (default threshold %g)\n",
                    ll::core::ToString(config.method).c_str(), distance,
                    ll::pipeline::IsMatch(config.method, distance, threshold) ? "same place"
                                                                              : "different places",
                    threshold);
    } catch (const std::exception& e) {  // lidarloop's errors name the file and the problem
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 0;
}

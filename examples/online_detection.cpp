// Online loop detection: scans arrive one at a time; each is compared with the scans more than
// 30 scans older and then stored. Usage: online_detection DATASET [height|range|ndt]
#include <cstdio>
#include <exception>

#include "lidarloop/lidarloop.hpp"  // every public header; link lidarloop::app

namespace ll = lidarloop;

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s DATASET [height|range|ndt]\n", argv[0]);
        return 2;
    }
    try {
        // [readme-snippet]
        const ll::io::Dataset dataset = ll::io::OpenDataset(argv[1]);  // KITTI, scan files, .3d
        ll::core::DescriptorConfig descriptor;                         // range histograms
        if (argc > 2) descriptor.method = ll::pipeline::ParseMethod(argv[2]);
        ll::pipeline::DetectorConfig detection;  // candidates > 30 scans back, default threshold
        ll::pipeline::LoopDetector detector(descriptor, detection);
        for (std::size_t i = 0; i < dataset.size(); ++i) {
            const ll::pipeline::LoopQuery query =
                detector.Process(dataset.LoadScan(i), static_cast<double>(i));
            if (const auto loop = query.loop())  // the verified loop (the first accepted candidate)
                std::printf("scan %zu revisits scan %zu (distance %.4f)\n", i,
                            query.candidates[*loop].index, query.candidates[*loop].distance);
        }
        // [readme-snippet]
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 0;
}

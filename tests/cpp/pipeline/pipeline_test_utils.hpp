#pragma once

// Random histograms for the pipeline tests: "places" whose scans differ by small perturbations,
// so that near neighbours exist as in a real sequence.

#include <random>
#include <vector>

#include "lidarloop/core/descriptor.hpp"

namespace lidarloop::test {

inline std::vector<double> Normalised(std::vector<double> h) {
    double total = 0.0;
    for (double v : h) total += v;
    for (double& v : h) v /= total;
    return h;
}

/// `count` histograms of `bins` buckets drawn around `places` random prototypes.
inline std::vector<std::vector<double>> ClusteredHistograms(std::size_t count, int bins, int places,
                                                            unsigned seed) {
    std::mt19937 rng(seed);
    std::exponential_distribution<double> weight(1.0);
    std::normal_distribution<double> noise(0.0, 0.05);
    std::vector<std::vector<double>> prototypes(static_cast<std::size_t>(places));
    for (auto& p : prototypes) {
        p.resize(static_cast<std::size_t>(bins));
        for (double& v : p) v = weight(rng);
    }
    std::vector<std::vector<double>> out;
    for (std::size_t i = 0; i < count; ++i) {
        std::vector<double> h = prototypes[rng() % prototypes.size()];
        for (double& v : h) v = std::max(1e-6, v * (1.0 + noise(rng)));
        out.push_back(Normalised(h));
    }
    return out;
}

inline core::Descriptor HistogramDescriptor(const std::vector<double>& mass) {
    core::Histogram h;
    h.mass = mass;
    return {core::Method::kHeight, h};
}

}  // namespace lidarloop::test

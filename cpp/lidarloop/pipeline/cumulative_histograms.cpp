#include "lidarloop/pipeline/cumulative_histograms.hpp"

#include <cmath>
#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::pipeline {

CumulativeHistograms::CumulativeHistograms(int bins) : bins_(bins) {
    if (bins < 1 || bins > 1'000'000) {
        throw core::ConfigError("histogram bins must be in [1, 1000000], got " +
                                std::to_string(bins));
    }
    stride_ = (bins + kLanes - 1) / kLanes * kLanes;
}

std::vector<float> CumulativeHistograms::MakeRow(std::span<const double> mass) const {
    if (mass.size() != static_cast<std::size_t>(bins_)) {
        throw core::ConfigError("histogram has " + std::to_string(mass.size()) +
                                " buckets, the database holds " + std::to_string(bins_));
    }
    std::vector<float> row(static_cast<std::size_t>(stride_), 0.0f);
    double running = 0.0;  // summed in double, stored in float
    for (std::size_t k = 0; k < mass.size(); ++k) {
        running += mass[k];
        row[k] = static_cast<float>(running);
    }
    return row;
}

std::size_t CumulativeHistograms::Add(std::span<const double> mass) {
    return AddRow(MakeRow(mass));
}

std::size_t CumulativeHistograms::AddRow(std::span<const float> row) {
    if (row.size() != static_cast<std::size_t>(stride_)) {
        throw core::ConfigError("cumulative row has " + std::to_string(row.size()) +
                                " values, expected " + std::to_string(stride_));
    }
    data_.insert(data_.end(), row.begin(), row.end());
    return size() - 1;
}

float CumulativeHistograms::L1(const float* a, const float* b, int count) {
    float partial[kLanes] = {};
    for (int i = 0; i < count; i += kLanes) {
        for (int lane = 0; lane < kLanes; ++lane) {
            partial[lane] += std::abs(a[i + lane] - b[i + lane]);
        }
    }
    float total = 0.0f;
    for (float p : partial) total += p;
    return total;
}

}  // namespace lidarloop::pipeline

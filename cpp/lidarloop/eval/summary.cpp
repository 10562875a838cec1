#include "lidarloop/eval/summary.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "lidarloop/core/error.hpp"

namespace lidarloop::eval {

double Quantile(std::span<const double> sorted, double q) {
    if (sorted.empty()) throw core::EmptyInputError("quantile of no values");
    if (!(q >= 0.0 && q <= 1.0)) {
        throw core::ConfigError("quantile level must be in [0, 1], got " + std::to_string(q));
    }
    const double position = q * static_cast<double>(sorted.size() - 1);
    const auto below = static_cast<std::size_t>(std::floor(position));
    const std::size_t above = std::min(below + 1, sorted.size() - 1);
    const double fraction = position - static_cast<double>(below);
    return sorted[below] + fraction * (sorted[above] - sorted[below]);
}

Summary Summarize(std::span<const double> values) {
    if (values.empty()) throw core::EmptyInputError("summary of no values");
    std::vector<double> sorted(values.begin(), values.end());
    double sum = 0.0;
    for (std::size_t i = 0; i < sorted.size(); ++i) {
        if (!std::isfinite(sorted[i])) {
            throw core::ConfigError("summary: value " + std::to_string(i) + " is not finite");
        }
        sum += sorted[i];
    }
    std::sort(sorted.begin(), sorted.end());
    Summary summary;
    summary.count = sorted.size();
    summary.mean = sum / static_cast<double>(sorted.size());
    summary.min = sorted.front();
    summary.p05 = Quantile(sorted, 0.05);
    summary.p25 = Quantile(sorted, 0.25);
    summary.median = Quantile(sorted, 0.5);
    summary.p75 = Quantile(sorted, 0.75);
    summary.p95 = Quantile(sorted, 0.95);
    summary.max = sorted.back();
    return summary;
}

DistinctivenessSummary SummarizeDistinctiveness(std::span<const BestMatch> matches) {
    std::vector<double> ratios;
    for (const auto& m : matches) {
        if (!std::isfinite(m.second_distance) || !std::isfinite(m.distance)) continue;
        ratios.push_back(m.second_distance == 0.0 ? 1.0 : m.distance / m.second_distance);
    }
    DistinctivenessSummary result;
    result.scans = matches.size();
    result.used = ratios.size();
    if (!ratios.empty()) result.ratio = Summarize(ratios);
    return result;
}

}  // namespace lidarloop::eval

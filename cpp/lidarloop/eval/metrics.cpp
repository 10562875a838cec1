#include "lidarloop/eval/metrics.hpp"

#include <algorithm>
#include <cmath>

#include "lidarloop/eval/detail/ratio.hpp"

namespace lidarloop::eval {

using detail::Ratio;

double Precision(const Confusion& c) { return Ratio(c.tp, c.tp + c.fp); }

double Recall(const Confusion& c) { return Ratio(c.tp, c.tp + c.fn); }

double FalsePositiveRate(const Confusion& c) { return Ratio(c.fp, c.fp + c.tn); }

double F1(const Confusion& c) { return Ratio(2 * c.tp, 2 * c.tp + c.fn + c.fp); }

double Mcc(const Confusion& c) {
    const auto tp = static_cast<double>(c.tp);
    const auto fp = static_cast<double>(c.fp);
    const auto tn = static_cast<double>(c.tn);
    const auto fn = static_cast<double>(c.fn);
    if (c.tp + c.fp == 0 || c.tp + c.fn == 0 || c.tn + c.fp == 0 || c.tn + c.fn == 0) return 0.0;
    // Four square roots instead of one of the product keep the intermediate below overflow.
    const double denominator =
        std::sqrt(tp + fp) * std::sqrt(tp + fn) * std::sqrt(tn + fp) * std::sqrt(tn + fn);
    return std::clamp((tp * tn - fp * fn) / denominator, -1.0, 1.0);
}

}  // namespace lidarloop::eval

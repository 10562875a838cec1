#include "lidarloop/eval/em.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::eval {
namespace {

constexpr double kLogSqrtTwoPi = 0.91893853320467274178;  // log(sqrt(2 pi))

void RequireInt(int value, int min, int max, const char* field) {
    if (value < min || value > max) {
        throw core::ConfigError(std::string("em.") + field + " must be in [" + std::to_string(min) +
                                ", " + std::to_string(max) + "], got " + std::to_string(value));
    }
}

double LogWeightedDensity(const GaussianComponent& c, double x) {
    const double z = (x - c.mean) / c.stddev;
    return std::log(c.weight) - std::log(c.stddev) - kLogSqrtTwoPi - 0.5 * z * z;
}

// Working state of one EM start: the parameters and the n x k responsibilities.
struct EmState {
    std::vector<GaussianComponent> components;
    std::vector<double> responsibility;  // row-major, n rows of k
};

// E-step: responsibilities for the current parameters; returns the log-likelihood
// (log-sum-exp per value so that far tails do not underflow to log(0)).
double ExpectationStep(std::span<const double> sample, EmState& state) {
    const std::size_t k = state.components.size();
    state.responsibility.resize(sample.size() * k);
    double log_likelihood = 0.0;
    for (std::size_t i = 0; i < sample.size(); ++i) {
        double* row = &state.responsibility[i * k];
        double largest = -std::numeric_limits<double>::infinity();
        for (std::size_t c = 0; c < k; ++c) {
            row[c] = LogWeightedDensity(state.components[c], sample[i]);
            largest = std::max(largest, row[c]);
        }
        double sum = 0.0;
        for (std::size_t c = 0; c < k; ++c) sum += (row[c] = std::exp(row[c] - largest));
        for (std::size_t c = 0; c < k; ++c) row[c] /= sum;
        log_likelihood += largest + std::log(sum);
    }
    return log_likelihood;
}

// M-step with the standard deviation floor; a component that lost all its values keeps its
// mean and spread with a weight of 0 (it no longer takes part).
void MaximisationStep(std::span<const double> sample, double min_stddev, EmState& state) {
    const std::size_t k = state.components.size();
    const auto n = static_cast<double>(sample.size());
    for (std::size_t c = 0; c < k; ++c) {
        double total = 0.0;
        double weighted_sum = 0.0;
        for (std::size_t i = 0; i < sample.size(); ++i) {
            total += state.responsibility[i * k + c];
            weighted_sum += state.responsibility[i * k + c] * sample[i];
        }
        GaussianComponent& component = state.components[c];
        component.weight = total / n;
        if (!(total > 1e-12 * n)) continue;
        component.mean = weighted_sum / total;
        double squares = 0.0;
        for (std::size_t i = 0; i < sample.size(); ++i) {
            const double d = sample[i] - component.mean;
            squares += state.responsibility[i * k + c] * d * d;
        }
        component.stddev = std::max(std::sqrt(squares / total), min_stddev);
    }
}

struct SampleStats {
    double mean = 0.0;
    double stddev = 0.0;
    std::vector<double> sorted;
};

SampleStats Describe(std::span<const double> sample) {
    SampleStats stats;
    stats.sorted.assign(sample.begin(), sample.end());
    std::sort(stats.sorted.begin(), stats.sorted.end());
    for (const double x : sample) stats.mean += x;
    stats.mean /= static_cast<double>(sample.size());
    double squares = 0.0;
    for (const double x : sample) squares += (x - stats.mean) * (x - stats.mean);
    stats.stddev = std::sqrt(squares / static_cast<double>(sample.size()));
    return stats;
}

// Start means: the sample's quantiles (c + 1/2) / k for start 0, random sample values for the
// others.
std::vector<double> StartMeans(const SampleStats& stats, int components, int restart,
                               std::mt19937_64& rng) {
    const auto k = static_cast<std::size_t>(components);
    std::vector<double> means(k);
    std::uniform_int_distribution<std::size_t> pick(0, stats.sorted.size() - 1);
    const auto last = static_cast<double>(stats.sorted.size() - 1);
    for (std::size_t c = 0; c < k; ++c) {
        const double q = (static_cast<double>(c) + 0.5) / static_cast<double>(k);
        means[c] = restart == 0 ? stats.sorted[static_cast<std::size_t>(q * last + 0.5)]
                                : stats.sorted[pick(rng)];
    }
    return means;
}

// Weights and deviations from one hard assignment of every value to its nearest start mean:
// starting all components with the sample's full spread makes 50 iterations too few to separate
// narrow components (the overlapping-scan one is narrow).
std::vector<GaussianComponent> StartParameters(std::span<const double> sample,
                                               const SampleStats& stats,
                                               const std::vector<double>& means,
                                               double min_stddev) {
    const std::size_t k = means.size();
    std::vector<double> count(k, 0.0);
    std::vector<double> squares(k, 0.0);
    for (const double x : sample) {
        std::size_t nearest = 0;
        for (std::size_t c = 1; c < k; ++c) {
            if (std::abs(x - means[c]) < std::abs(x - means[nearest])) nearest = c;
        }
        count[nearest] += 1.0;
        squares[nearest] += (x - means[nearest]) * (x - means[nearest]);
    }
    std::vector<GaussianComponent> start(k);
    const auto n = static_cast<double>(sample.size());
    for (std::size_t c = 0; c < k; ++c) {
        // An empty cell still gets a small share, so that the component can grow.
        start[c].weight = std::max(count[c], 1.0) / (n + static_cast<double>(k));
        start[c].mean = means[c];
        start[c].stddev = count[c] >= 2.0 ? std::max(std::sqrt(squares[c] / count[c]), min_stddev)
                                          : stats.stddev / static_cast<double>(k);
    }
    double total = 0.0;
    for (const auto& c : start) total += c.weight;
    for (auto& c : start) c.weight /= total;
    return start;
}

MixtureFit RunStart(std::span<const double> sample, const EmConfig& config, double min_stddev,
                    std::vector<GaussianComponent> start) {
    EmState state{std::move(start), {}};
    MixtureFit fit;
    fit.log_likelihood = ExpectationStep(sample, state);
    for (fit.iterations = 1; fit.iterations <= config.max_iterations; ++fit.iterations) {
        MaximisationStep(sample, min_stddev, state);
        const double next = ExpectationStep(sample, state);
        const double change = std::abs(next - fit.log_likelihood);
        fit.log_likelihood = next;
        if (change <= config.tolerance * (1.0 + std::abs(next))) {
            fit.converged = true;
            break;
        }
    }
    fit.iterations = std::min(fit.iterations, config.max_iterations);
    fit.components = std::move(state.components);
    return fit;
}

}  // namespace

void EmConfig::Validate() const {
    RequireInt(components, 2, 16, "components");
    RequireInt(restarts, 1, 10'000, "restarts");
    RequireInt(max_iterations, 1, 100'000, "max_iterations");
    if (!std::isfinite(tolerance) || tolerance < 0.0) {
        throw core::ConfigError("em.tolerance must be a finite number >= 0, got " +
                                std::to_string(tolerance));
    }
    if (!(min_stddev_fraction > 0.0 && min_stddev_fraction <= 1.0)) {
        throw core::ConfigError("em.min_stddev_fraction must be in (0, 1], got " +
                                std::to_string(min_stddev_fraction));
    }
}

double GaussianComponent::WeightedDensity(double x) const {
    const double z = (x - mean) / stddev;
    return weight * std::exp(-0.5 * z * z) / (stddev * std::sqrt(2.0 * std::numbers::pi));
}

double MixtureFit::Density(double x) const {
    double sum = 0.0;
    for (const auto& component : components) sum += component.WeightedDensity(x);
    return sum;
}

MixtureFit FitGaussianMixture(std::span<const double> sample, const EmConfig& config) {
    config.Validate();
    if (sample.size() < static_cast<std::size_t>(config.components)) {
        throw core::EmptyInputError("EM: " + std::to_string(sample.size()) + " values cannot fit " +
                                    std::to_string(config.components) + " Gaussians");
    }
    for (std::size_t i = 0; i < sample.size(); ++i) {
        if (!std::isfinite(sample[i])) {
            throw core::ConfigError("EM: value " + std::to_string(i) + " is not finite");
        }
    }
    const SampleStats stats = Describe(sample);
    if (stats.sorted.front() == stats.sorted.back())
        throw core::ConfigError("EM: all values are equal");
    const double min_stddev = config.min_stddev_fraction * stats.stddev;
    std::mt19937_64 rng(config.seed);
    MixtureFit best;
    for (int restart = 0; restart < config.restarts; ++restart) {
        const auto means = StartMeans(stats, config.components, restart, rng);
        MixtureFit fit =
            RunStart(sample, config, min_stddev, StartParameters(sample, stats, means, min_stddev));
        fit.restart = restart;
        if (restart == 0 || fit.log_likelihood > best.log_likelihood) best = std::move(fit);
    }
    std::sort(
        best.components.begin(), best.components.end(),
        [](const GaussianComponent& a, const GaussianComponent& b) { return a.mean < b.mean; });
    return best;
}

std::optional<double> CrossingBetweenMeans(const GaussianComponent& first,
                                           const GaussianComponent& second) {
    const GaussianComponent& a = first.mean <= second.mean ? first : second;
    const GaussianComponent& b = first.mean <= second.mean ? second : first;
    if (!(a.mean < b.mean) || !(a.weight > 0.0) || !(b.weight > 0.0)) return std::nullopt;
    // f(x) = log(wa Na(x)) - log(wb Nb(x)) = qa x^2 + qb x + qc.
    const double ia = 1.0 / (a.stddev * a.stddev);
    const double ib = 1.0 / (b.stddev * b.stddev);
    const double qa = 0.5 * (ib - ia);
    const double qb = a.mean * ia - b.mean * ib;
    const double qc = std::log(a.weight * b.stddev / (b.weight * a.stddev)) -
                      0.5 * a.mean * a.mean * ia + 0.5 * b.mean * b.mean * ib;
    std::vector<double> roots;
    if (qa == 0.0) {
        roots.push_back(-qc / qb);  // qb = (ma - mb) / s^2 != 0
    } else {
        const double discriminant = qb * qb - 4.0 * qa * qc;
        if (discriminant < 0.0) return std::nullopt;
        // The cancellation-free pair of roots (also right for nearly equal deviations, where
        // one root runs off to infinity).
        const double q = -0.5 * (qb + std::copysign(std::sqrt(discriminant), qb));
        roots.push_back(q / qa);
        if (q != 0.0) roots.push_back(qc / q);
    }
    std::sort(roots.begin(), roots.end());
    for (const double x : roots) {
        // The lower-mean component dominates left of x: f falls through 0.
        if (x >= a.mean && x <= b.mean && 2.0 * qa * x + qb < 0.0) return x;
    }
    return std::nullopt;
}

DifferenceThreshold EstimateDifferenceThreshold(std::span<const double> smallest_differences,
                                                const EmConfig& config) {
    config.Validate();
    std::vector<double> finite;
    finite.reserve(smallest_differences.size());
    for (const double x : smallest_differences) {
        if (std::isfinite(x)) finite.push_back(x);
    }
    DifferenceThreshold result;
    result.values_skipped = smallest_differences.size() - finite.size();
    // A results file may give few scans a match, or one distance to all (a yes/no detector):
    // nothing to fit, which is a finding about the detector, not an error of the evaluation.
    const bool all_equal =
        std::adjacent_find(finite.begin(), finite.end(), std::not_equal_to<>()) == finite.end();
    if (finite.size() < static_cast<std::size_t>(config.components) || all_equal) return result;
    result.values_used = finite.size();
    result.fit = FitGaussianMixture(finite, config);
    result.t_d = CrossingBetweenMeans(result.fit.components[0], result.fit.components[1]);
    return result;
}

}  // namespace lidarloop::eval

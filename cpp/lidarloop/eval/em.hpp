#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace lidarloop::eval {

/// Expectation maximisation for a 1-D Gaussian mixture (Magnusson II-E: three Gaussians fitted
/// to every scan's smallest difference, "a maximum of 50 EM iterations from randomly
/// initialized start parameters", keeping the best likelihood).
struct EmConfig {
    int components = 3;       ///< Gaussians in the mixture, 2..16; Magnusson uses 3
    int restarts = 10;        ///< independent starts, 1..10'000; the best log-likelihood wins
    int max_iterations = 50;  ///< EM iterations per start, 1..100'000; Magnusson: 50
    /// A start stops early once the log-likelihood changes by at most
    /// tolerance * (1 + |log-likelihood|); >= 0 (0 runs every iteration).
    double tolerance = 1e-10;
    /// Lower bound of every standard deviation as a fraction of the sample's standard deviation,
    /// in (0, 1]: keeps a component from collapsing onto one value (infinite likelihood).
    double min_stddev_fraction = 1e-2;
    std::uint64_t seed = 1;  ///< seeds the random starts (std::mt19937_64)

    /// Throws core::ConfigError naming the invalid field (prefix "em.").
    void Validate() const;
};

/// One weighted Gaussian of a mixture.
struct GaussianComponent {
    double weight = 0.0;  ///< mixing weight, the weights sum to 1
    double mean = 0.0;    ///< same unit as the sample
    double stddev = 1.0;  ///< > 0, same unit as the sample

    /// weight * N(x; mean, stddev^2), the component's share of the mixture density.
    double WeightedDensity(double x) const;
};

/// A fitted mixture.
struct MixtureFit {
    std::vector<GaussianComponent> components;  ///< sorted by mean, ascending
    double log_likelihood = 0.0;                ///< of the sample under the mixture (natural log)
    int restart = 0;     ///< which start gave it (0 = the quantile start, see FitGaussianMixture)
    int iterations = 0;  ///< EM iterations of that start
    bool converged = false;  ///< stopped by the tolerance rather than by max_iterations

    /// The mixture density at x.
    double Density(double x) const;
};

/// Fits the mixture by EM. Start 0 puts the means at the sample's quantiles
/// (k + 1/2) / components; starts 1.. draw the means from random sample values (seeded); the
/// start weights and deviations come from assigning every value to its nearest start mean.
/// Non-finite values must be removed
/// by the caller. Throws core::ConfigError for an invalid config, core::EmptyInputError when
/// the sample has fewer values than components, and core::ConfigError when a value is not finite or
/// all values are equal. O(restarts * max_iterations * n * components). Thread-safe.
MixtureFit FitGaussianMixture(std::span<const double> sample, const EmConfig& config = {});

/// Where the weighted densities of `first` and `second` cross between their means: the root of
/// the quadratic log(w1 N1(x)) = log(w2 N2(x)) in [min mean, max mean] at which the
/// lower-mean component stops dominating (smallest such root); a linear equation when the
/// standard deviations are equal. nullopt when there is no such crossing (one component
/// dominates the whole interval, or equal means). O(1).
std::optional<double> CrossingBetweenMeans(const GaussianComponent& first,
                                           const GaussianComponent& second);

/// Magnusson's t_d from every scan's smallest difference.
struct DifferenceThreshold {
    MixtureFit fit;  ///< no components when there was nothing to fit (see Fitted)
    /// Crossing of the first two components (by mean); nullopt when they do not cross or
    /// nothing was fitted.
    std::optional<double> t_d;
    std::size_t values_used = 0;     ///< finite values fitted (0 when nothing was fitted)
    std::size_t values_skipped = 0;  ///< non-finite values left out (scans without a match)

    /// False when there were fewer finite values than components, or all were equal.
    bool Fitted() const { return !fit.components.empty(); }
};

/// Fits the mixture to the finite values of `smallest_differences` (BestMatch::distance per
/// scan) and returns the crossing of its first two components (Magnusson II-E, fig. 2). With
/// fewer finite values than components, or all of them equal, nothing is fitted (Fitted() is
/// false, no t_d). Throws core::ConfigError for an invalid config.
DifferenceThreshold EstimateDifferenceThreshold(std::span<const double> smallest_differences,
                                                const EmConfig& config = {});

}  // namespace lidarloop::eval

#pragma once

// Internal: a small counter-based random generator. The simulator derives every random choice
// from (seed, purpose, index) through these functions so that any scan or block can be generated
// on its own, in any order and on any thread, with the same result. Not installed.

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <numbers>

namespace lidarloop::sim::detail {

/// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix.
constexpr std::uint64_t Mix64(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

/// A hash of several 64-bit values, order-sensitive.
constexpr std::uint64_t HashValues(std::initializer_list<std::uint64_t> values) {
    std::uint64_t h = 0x243f6a8885a308d3ULL;
    for (const std::uint64_t v : values) h = Mix64(h ^ Mix64(v));
    return h;
}

/// Distinct streams of randomness drawn from one seed.
enum class Stream : std::uint64_t {
    kTerrain = 1,
    kBlock = 2,
    kStreet = 3,
    kSpacing = 4,
    kOdometry = 5,
    kScan = 6,
    kEnclosure = 7,
};

constexpr std::uint64_t StreamSeed(std::uint64_t seed, Stream stream,
                                   std::initializer_list<std::int64_t> indices = {}) {
    std::uint64_t h = HashValues({seed, static_cast<std::uint64_t>(stream)});
    for (const std::int64_t i : indices) h = HashValues({h, static_cast<std::uint64_t>(i)});
    return h;
}

/// Sequential SplitMix64 generator with the few distributions the simulator needs. Its output
/// depends only on the seed (no std:: distributions, whose algorithms differ between libraries).
/// Draw once per statement: the order of a call's arguments is the compiler's (GCC right to left,
/// clang left to right). Scenes that drew within one call now draw statement by statement in
/// GCC's order, the one the recorded sequences were made with (test
/// Simulator.ASeedGivesTheSameScansWhateverTheCompiler).
class Random {
public:
    explicit Random(std::uint64_t seed) : state_(seed) {}

    std::uint64_t NextU64() {
        state_ += 0x9e3779b97f4a7c15ULL;
        return Mix64(state_);
    }

    /// Uniform in [0, 1) with 53 random bits.
    double Uniform() { return static_cast<double>(NextU64() >> 11) * 0x1.0p-53; }

    /// Uniform in [lo, hi).
    double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }

    /// Uniform integer in [lo, hi], both included.
    int UniformInt(int lo, int hi) {
        const auto span = static_cast<std::uint64_t>(static_cast<std::int64_t>(hi) - lo + 1);
        return lo + static_cast<int>(NextU64() % span);
    }

    bool Bernoulli(double p) { return Uniform() < p; }

    /// Standard normal by Box-Muller (one of the pair; the other is dropped for simplicity).
    double Normal() {
        const double u1 = 1.0 - Uniform();  // (0, 1], so the log is finite
        const double u2 = Uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
    }

private:
    std::uint64_t state_;
};

}  // namespace lidarloop::sim::detail

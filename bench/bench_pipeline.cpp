// Google Benchmark kernels of the detection pipeline. Run: ./build/bench/bench_pipeline
// The stored histograms are synthetic: smooth random "places" (mixtures of two bumps over the
// buckets) and, per place, scans that perturb them slightly, so that near neighbours exist as
// in a real sequence. Real data may prune differently; `lidarloop bench` measures a dataset.
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "lidarloop/pipeline/cumulative_histograms.hpp"
#include "lidarloop/pipeline/descriptor_database.hpp"
#include "lidarloop/pipeline/histogram_index.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

namespace lidarloop::bench {
namespace {

constexpr int kBins = 100;

std::vector<double> PlaceHistogram(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double c1 = 10 + 30 * u(rng), c2 = 40 + 50 * u(rng);
    const double w1 = 2 + 6 * u(rng), w2 = 3 + 10 * u(rng), mix = u(rng);
    std::vector<double> h(kBins);
    double total = 0.0;
    for (int k = 0; k < kBins; ++k) {
        h[static_cast<std::size_t>(k)] = mix * std::exp(-0.5 * std::pow((k - c1) / w1, 2)) +
                                         (1 - mix) * std::exp(-0.5 * std::pow((k - c2) / w2, 2)) +
                                         1e-3;
        total += h[static_cast<std::size_t>(k)];
    }
    for (double& v : h) v /= total;
    return h;
}

// `count` scans: every 100 consecutive scans revisit one of count/100 places, perturbed.
std::vector<std::vector<double>> SyntheticHistograms(std::size_t count, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.03);
    std::vector<std::vector<double>> histograms;
    std::vector<double> place;
    for (std::size_t i = 0; i < count; ++i) {
        if (i % 100 == 0) place = PlaceHistogram(rng);
        std::vector<double> h = place;
        double total = 0.0;
        for (double& v : h) total += (v *= std::max(0.0, 1.0 + noise(rng)));
        for (double& v : h) v /= total;
        histograms.push_back(std::move(h));
    }
    return histograms;
}

pipeline::CumulativeHistograms SyntheticStore(std::size_t count, unsigned seed) {
    pipeline::CumulativeHistograms store(kBins);
    for (const std::vector<double>& h : SyntheticHistograms(count, seed)) store.Add(h);
    return store;
}

void BM_WassersteinOnCumulativeRows(benchmark::State& state) {
    const auto store = SyntheticStore(2, 1);
    for (auto _ : state) benchmark::DoNotOptimize(store.Distance(0, 1));
}
BENCHMARK(BM_WassersteinOnCumulativeRows)->Unit(benchmark::kNanosecond);

void BM_SimilarityMatrix(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    core::DescriptorConfig config;
    config.histogram.bins = kBins;
    pipeline::DescriptorDatabase database(config);
    for (std::vector<double>& mass : SyntheticHistograms(n, 2)) {
        core::Histogram histogram;
        histogram.mass = std::move(mass);
        database.Add({core::Method::kHeight, std::move(histogram)}, 0.0);
    }
    const auto execution =
        state.range(1) != 0 ? pipeline::Execution::kParallel : pipeline::Execution::kSerial;
    for (auto _ : state) {
        benchmark::DoNotOptimize(pipeline::ComputeSimilarityMatrix(database, execution));
    }
    state.counters["pairs"] = static_cast<double>(n * (n - 1) / 2);
    state.counters["per_pair"] = benchmark::Counter(
        static_cast<double>(n * (n - 1) / 2),
        benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SimilarityMatrix)
    ->Args({4541, 0})
    ->Args({4541, 1})
    ->ArgNames({"scans", "parallel"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

const pipeline::CumulativeHistograms& MillionStore() {
    static const pipeline::CumulativeHistograms store = SyntheticStore(1'000'000, 3);
    return store;
}

void BM_QueryTop1(benchmark::State& state) {
    const auto& store = MillionStore();
    static const pipeline::HistogramIndex index = [&] {
        pipeline::HistogramIndex built(store);
        built.InsertAll();
        return built;
    }();
    const auto queries = SyntheticStore(64, 4);  // new scans of other places
    const bool brute = state.range(0) != 0;
    std::size_t q = 0;
    for (auto _ : state) {
        const float* row = queries.Row(q++ % queries.size());
        benchmark::DoNotOptimize(brute ? index.BruteForce(row, 1) : index.Search(row, 1));
    }
    state.counters["stored"] = static_cast<double>(store.size());
}
BENCHMARK(BM_QueryTop1)->Arg(0)->Arg(1)->ArgName("brute_force")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace lidarloop::bench

BENCHMARK_MAIN();

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
#include "lidarloop/pipeline/loop_detector.hpp"
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

// The search a query with few scans within the odometry's reach makes of the online index
// (SearchReachable doubles its request until k reachable ones are found): the k best of an
// hour at 10 Hz (36,000 scans), up to the whole ranking.
void BM_QueryDeep(benchmark::State& state) {
    static const pipeline::CumulativeHistograms store = SyntheticStore(36'000, 5);
    static const pipeline::HistogramIndex index = [&] {
        pipeline::HistogramIndex built(store);
        built.InsertAll();
        return built;
    }();
    const auto queries = SyntheticStore(64, 6);
    const auto k = static_cast<std::size_t>(state.range(0));
    std::size_t q = 0;
    for (auto _ : state) benchmark::DoNotOptimize(index.Search(queries.Row(q++ % 64), k));
    state.counters["stored"] = static_cast<double>(store.size());
}
BENCHMARK(BM_QueryDeep)
    ->Arg(10)
    ->Arg(1280)
    ->Arg(40960)
    ->ArgName("k")
    ->Unit(benchmark::kMillisecond);

// The online detector's candidate search with the odometry after an hour at 10 Hz: 36,000
// scans 1.5 m apart along a straight road (no revisit: no scan within reach, the worst case),
// a gate that passes a loop within 3 m of the odometry's pose; Process of one more scan (verify
// on, as the reach applies only then, but the scans come unprepared: nothing is registered).
// bounded 0: the gate does not say its allowance, so the search ranks the whole
// run before it finds that nothing is in reach.
void BM_OnlineSearchWithOdometry(benchmark::State& state) {
    core::DescriptorConfig config;
    config.method = core::Method::kHeight;
    config.histogram.bins = kBins;
    pipeline::DetectorConfig detector;
    pipeline::LoopDetector online(config, detector);
    const auto pose_of = [](std::size_t i) {
        core::Transform T = core::Transform::Identity();
        T.translation().x() = 1.5 * static_cast<double>(i);
        return T;
    };
    const auto descriptor_of = [](std::vector<double> mass) {
        core::Histogram histogram;
        histogram.mass = std::move(mass);
        return core::Descriptor{core::Method::kHeight, std::move(histogram)};
    };
    const std::vector<std::vector<double>> histograms = SyntheticHistograms(36'064, 7);
    std::size_t i = 0;
    for (; i < 36'000; ++i)  // without the gate: cheap to fill
        online.Process(descriptor_of(histograms[i]), 0.1 * static_cast<double>(i), {}, pose_of(i));
    pipeline::OdometryGate gate;
    gate.rejects = [](const core::Transform& T_loop, const core::Transform& T_odometry, double) {
        return (T_loop.translation() - T_odometry.translation()).norm() > 3.0;
    };
    if (state.range(0) != 0) gate.translation_allowance_m = [](double) { return 3.0; };
    online.SetOdometryGate(gate);
    for (auto _ : state) {
        const std::size_t next = i++;
        benchmark::DoNotOptimize(online.Process(descriptor_of(histograms[next % histograms.size()]),
                                                0.1 * static_cast<double>(next), {},
                                                pose_of(next)));
    }
}
BENCHMARK(BM_OnlineSearchWithOdometry)
    ->Arg(0)
    ->Arg(1)
    ->ArgName("bounded")
    ->Iterations(50)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace lidarloop::bench

BENCHMARK_MAIN();

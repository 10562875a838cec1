// Google Benchmark kernels of the descriptors. Run: ./build/bench/bench_kernels
#include <cstdint>
#include <iterator>
#include <map>
#include <random>
#include <utility>

#include <benchmark/benchmark.h>

#include "lidarloop/core/histogram.hpp"
#include "lidarloop/core/ndt/ndt_cells.hpp"
#include "lidarloop/core/ndt/ndt_descriptor.hpp"
#include "lidarloop/core/scancontext/scancontext.hpp"
#include "lidarloop/core/scancontext/scancontext_distance.hpp"
#include "lidarloop/core/wasserstein.hpp"
#include "lidarloop/sim/simulator.hpp"
#include "synthetic_scan.hpp"

namespace lidarloop::bench {
namespace {

const core::PointCloud& Scan() {
    static const core::PointCloud scan = SyntheticHdl64Scan(1);
    return scan;
}

void SetPointCounters(benchmark::State& state) {
    state.counters["points"] = static_cast<double>(Scan().size());
    state.counters["per_point"] = benchmark::Counter(
        static_cast<double>(Scan().size()),
        benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_HeightHistogram(benchmark::State& state) {
    const core::HistogramConfig config;
    for (auto _ : state) {
        benchmark::DoNotOptimize(core::ComputeHistogram(Scan(), core::Projection::kHeight, config));
    }
    SetPointCounters(state);
}
BENCHMARK(BM_HeightHistogram)->Unit(benchmark::kMicrosecond);

void BM_RangeHistogram(benchmark::State& state) {
    const core::HistogramConfig config;
    for (auto _ : state) {
        benchmark::DoNotOptimize(core::ComputeHistogram(Scan(), core::Projection::kRange, config));
    }
    SetPointCounters(state);
}
BENCHMARK(BM_RangeHistogram)->Unit(benchmark::kMicrosecond);

void BM_Wasserstein(benchmark::State& state) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<double> g(static_cast<std::size_t>(state.range(0)));
    std::vector<double> h(g.size());
    for (auto& v : g) v = u(rng);
    for (auto& v : h) v = u(rng);
    for (auto _ : state) {
        benchmark::DoNotOptimize(core::WassersteinDistance(g, h));
        benchmark::ClobberMemory();
    }
}
BENCHMARK(BM_Wasserstein)->Arg(100)->Unit(benchmark::kNanosecond);

// Scan Context (Kim & Kim 2018) of the 120k-point scan: 20 rings x 60 sectors, 80 m. Target
// (issue 27): <= 1 ms.
void BM_ScanContext(benchmark::State& state) {
    const core::ScanContextConfig config;
    for (auto _ : state) benchmark::DoNotOptimize(core::ComputeScanContext(Scan(), config));
    SetPointCounters(state);
}
BENCHMARK(BM_ScanContext)->Unit(benchmark::kMicrosecond);

// The column-shift distance of two prepared descriptors (all 60 shifts x 20 rings), of the scan
// against itself turned by 50 degrees (dense: every column occupied). Target (issue 27): <= 3 us.
void BM_ScanContextDistance(benchmark::State& state) {
    const core::ScanContextConfig config;
    core::PointCloud turned = SyntheticHdl64Scan(2);
    const Eigen::Matrix3f R = Eigen::AngleAxisf(0.87f, Eigen::Vector3f::UnitZ()).toRotationMatrix();
    for (Eigen::Vector3f& p : turned) p = R * p;
    const core::ScanContextColumns a(core::ComputeScanContext(Scan(), config));
    const core::ScanContextColumns b(core::ComputeScanContext(turned, config));
    state.counters["occupied_columns"] = a.occupied_columns();
    for (auto _ : state) {
        benchmark::DoNotOptimize(core::CompareScanContexts(a, b));
        benchmark::ClobberMemory();
    }
}
BENCHMARK(BM_ScanContextDistance)->Unit(benchmark::kNanosecond);

// The cells as the descriptor computes them: into columns whose memory is reused across scans.
void BM_NdtCells(benchmark::State& state) {
    core::NdtCellColumns cells;
    for (auto _ : state) {
        core::ComputeNdtCellColumns(Scan(), 0.5, 5, cells);
        benchmark::DoNotOptimize(cells.point_count.data());
    }
    SetPointCounters(state);
}
BENCHMARK(BM_NdtCells)->Unit(benchmark::kMillisecond);

void BM_NdtDescriptorSet(benchmark::State& state) {
    core::NdtConfig config;
    config.regrid_rotations = state.range(0) != 0;
    std::size_t descriptors = 0;
    for (auto _ : state) {
        const auto set = core::ComputeNdtDescriptorSet(Scan(), config);
        descriptors = set.descriptors.size();
        benchmark::DoNotOptimize(set);
    }
    state.counters["descriptors"] = static_cast<double>(descriptors);
    SetPointCounters(state);
}
BENCHMARK(BM_NdtDescriptorSet)->Arg(0)->Arg(1)->ArgName("regrid")->Unit(benchmark::kMillisecond);

// Scan 100 of a simulated HDL-64E sequence (~116k points) of each scene: the town (urban:
// buildings, trees, poles, cars; about 1.5x the classified cells of the plane-and-walls scan, the
// case the 10 ms is for), rural roads, a self-similar mine and an office floor, whose
// walls and ceilings give other numbers of rotation candidates.
constexpr sim::SceneType kScenes[] = {sim::SceneType::kUrban, sim::SceneType::kRural,
                                      sim::SceneType::kMine, sim::SceneType::kIndoor};

const core::PointCloud& SimulatedScan(sim::SceneType scene, int index = 100) {
    static std::map<std::pair<sim::SceneType, int>, core::PointCloud> scans;
    const auto key = std::make_pair(scene, index);
    auto found = scans.find(key);
    if (found != scans.end()) return found->second;
    sim::SimulationConfig config;
    config.scene = scene;
    config.route.type = sim::RouteType::kUTurn;
    config.sensor.model = sim::SensorModel::kHdl64;
    config.scans = 300;
    config.seed = 3;
    return scans.emplace(key, sim::Simulator(config).Scan(index)).first->second;
}

void BM_NdtDescriptorSetScene(benchmark::State& state) {
    const sim::SceneType scene = kScenes[static_cast<std::size_t>(state.range(0))];
    const core::PointCloud& scan = SimulatedScan(scene);
    const core::NdtConfig config;
    std::size_t descriptors = 0;
    std::size_t cells = 0;
    for (auto _ : state) {
        const auto set = core::ComputeNdtDescriptorSet(scan, config);
        descriptors = set.descriptors.size();
        cells = static_cast<std::size_t>(set.descriptors.front().total);
        benchmark::DoNotOptimize(set);
    }
    state.SetLabel(sim::ToString(scene));
    state.counters["descriptors"] = static_cast<double>(descriptors);
    state.counters["classified_cells"] = static_cast<double>(cells);
    state.counters["points"] = static_cast<double>(scan.size());
    state.counters["per_point"] = benchmark::Counter(
        static_cast<double>(scan.size()),
        benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_NdtDescriptorSetScene)
    ->DenseRange(0, static_cast<std::int64_t>(std::size(kScenes)) - 1)
    ->ArgName("scene")
    ->Unit(benchmark::kMillisecond);

void BM_NdtDifference(benchmark::State& state) {
    const core::NdtConfig config;
    const auto a = core::ComputeNdtDescriptorSet(Scan(), config);
    const auto b = core::ComputeNdtDescriptorSet(SyntheticHdl64Scan(3), config);
    for (auto _ : state) {
        benchmark::DoNotOptimize(core::NdtDifference(a.descriptors[0], b.descriptors[0]));
    }
}
BENCHMARK(BM_NdtDifference)->Unit(benchmark::kNanosecond);

void BM_NdtSetDifference(benchmark::State& state) {
    const core::NdtConfig config;
    const auto a = core::ComputeNdtDescriptorSet(Scan(), config);
    const auto b = core::ComputeNdtDescriptorSet(SyntheticHdl64Scan(3), config);
    for (auto _ : state) benchmark::DoNotOptimize(core::NdtSetDifference(a, b));
    state.counters["pairs"] = static_cast<double>(a.descriptors.size() * b.descriptors.size());
}
BENCHMARK(BM_NdtSetDifference)->Unit(benchmark::kNanosecond);

// sigma' of two town scans (urban scans 100 and 200), whose sets hold several rotation
// candidates each, as grid-like streets give (ground and two wall directions are ambiguous peaks).
void BM_NdtSetDifferenceTown(benchmark::State& state) {
    const core::NdtConfig config;
    const auto a = core::ComputeNdtDescriptorSet(SimulatedScan(sim::SceneType::kUrban), config);
    const auto b =
        core::ComputeNdtDescriptorSet(SimulatedScan(sim::SceneType::kUrban, 200), config);
    for (auto _ : state) benchmark::DoNotOptimize(core::NdtSetDifference(a, b));
    state.counters["pairs"] = static_cast<double>(a.descriptors.size() * b.descriptors.size());
}
BENCHMARK(BM_NdtSetDifferenceTown)->Unit(benchmark::kNanosecond);

}  // namespace
}  // namespace lidarloop::bench

BENCHMARK_MAIN();

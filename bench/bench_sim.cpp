// Google Benchmark of the LiDAR simulator: one scan ray cast per iteration, with noise and
// dropouts. Run: ./build/bench/bench_sim
#include <benchmark/benchmark.h>

#include "lidarloop/sim/simulator.hpp"

namespace lidarloop::bench {
namespace {

sim::SimulationConfig Config(sim::SceneType scene, sim::SensorModel model) {
    sim::SimulationConfig config;
    config.scene = scene;
    config.route.type = sim::RouteType::kGrid;
    config.sensor.model = model;
    config.scans = 200;
    return config;
}

void ScanLoop(benchmark::State& state, const sim::Simulator& simulator) {
    std::size_t index = 0;
    std::size_t points = 0;
    for (auto _ : state) {
        const core::PointCloud cloud = simulator.Scan(index);
        points += cloud.size();
        benchmark::DoNotOptimize(cloud.data());
        index = (index + 7) % simulator.size();  // different places, different scenes in view
    }
    state.counters["rays"] = static_cast<double>(simulator.beam_directions().size());
    state.counters["points"] =
        static_cast<double>(points) / static_cast<double>(state.iterations());
}

void BM_ScanHdl64Urban(benchmark::State& state) {
    static const sim::Simulator simulator(Config(sim::SceneType::kUrban, sim::SensorModel::kHdl64));
    ScanLoop(state, simulator);
}
BENCHMARK(BM_ScanHdl64Urban)->Unit(benchmark::kMillisecond);

void BM_ScanVlp16Urban(benchmark::State& state) {
    static const sim::Simulator simulator(Config(sim::SceneType::kUrban, sim::SensorModel::kVlp16));
    ScanLoop(state, simulator);
}
BENCHMARK(BM_ScanVlp16Urban)->Unit(benchmark::kMillisecond);

void BM_ScanHdl64Mine(benchmark::State& state) {
    static const sim::Simulator simulator(Config(sim::SceneType::kMine, sim::SensorModel::kHdl64));
    ScanLoop(state, simulator);
}
BENCHMARK(BM_ScanHdl64Mine)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace lidarloop::bench

BENCHMARK_MAIN();

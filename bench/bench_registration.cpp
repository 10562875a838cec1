// Google Benchmark kernels of geometric verification (docs/verification.md). Run:
//   taskset -c 1 ./build/bench/bench_registration
// The scans are simulated (urban U-turn route, exact ground truth): a revisit driven in the
// opposite direction (a true loop) and two places 60+ m apart (a pair that must be rejected),
// for the HDL-64E and the VLP-16. `lidarloop bench --verify-queries N` measures a whole dataset.
#include <stdexcept>
#include <string>

#include <benchmark/benchmark.h>

#include "lidarloop/registration/coarse_alignment.hpp"
#include "lidarloop/registration/icp.hpp"
#include "lidarloop/registration/prepared_scan.hpp"
#include "lidarloop/registration/verification.hpp"
#include "lidarloop/sim/simulator.hpp"

namespace lidarloop::bench {
namespace {

using registration::PreparedScan;
using registration::VerificationConfig;

// The raw and prepared scans of one query and its two candidates.
struct PairScans {
    core::PointCloud query_raw;
    PreparedScan query;
    PreparedScan revisit;    // the same place, driven the other way
    PreparedScan elsewhere;  // a place at least 60 m away
    core::Transform T_revisit_query = core::Transform::Identity();  // ground truth
};

double Distance(const sim::Simulator& simulator, std::size_t a, std::size_t b) {
    return (simulator.GroundTruthPose(a).T_world_sensor.translation() -
            simulator.GroundTruthPose(b).T_world_sensor.translation())
        .norm();
}

bool Opposite(const sim::Simulator& simulator, std::size_t a, std::size_t b) {
    return simulator.GroundTruthPose(a).T_world_sensor.linear().col(0).dot(
               simulator.GroundTruthPose(b).T_world_sensor.linear().col(0)) < -0.9;
}

PairScans MakePairScans(sim::SensorModel sensor) {
    sim::SimulationConfig config;
    config.scene = sim::SceneType::kUrban;
    config.route.type = sim::RouteType::kUTurn;
    config.sensor.model = sensor;
    config.scans = 200;
    const sim::Simulator simulator(config);
    for (std::size_t query = 60; query < simulator.size(); ++query) {
        for (std::size_t revisit = 0; revisit + 30 < query; ++revisit) {
            if (!Opposite(simulator, query, revisit) || Distance(simulator, query, revisit) >= 5)
                continue;
            std::size_t elsewhere = 0;
            while (Distance(simulator, query, elsewhere) < 60) ++elsewhere;
            const VerificationConfig defaults;
            PairScans scans;
            scans.query_raw = simulator.Scan(query);
            scans.query = registration::PrepareScan(scans.query_raw, defaults.reduction);
            scans.revisit = registration::PrepareScan(simulator.Scan(revisit), defaults.reduction);
            scans.elsewhere =
                registration::PrepareScan(simulator.Scan(elsewhere), defaults.reduction);
            scans.T_revisit_query = simulator.GroundTruthPose(revisit).T_world_sensor.inverse() *
                                    simulator.GroundTruthPose(query).T_world_sensor;
            return scans;
        }
    }
    throw std::runtime_error("no opposite-direction revisit in the simulated route");
}

const PairScans& Scans(sim::SensorModel sensor) {
    static const PairScans hdl64 = MakePairScans(sim::SensorModel::kHdl64);
    static const PairScans vlp16 = MakePairScans(sim::SensorModel::kVlp16);
    return sensor == sim::SensorModel::kHdl64 ? hdl64 : vlp16;
}

sim::SensorModel SensorOf(const benchmark::State& state) {
    return state.range(0) == 64 ? sim::SensorModel::kHdl64 : sim::SensorModel::kVlp16;
}

void BM_PrepareScan(benchmark::State& state) {
    const PairScans& scans = Scans(SensorOf(state));
    const VerificationConfig config;
    for (auto _ : state) {
        benchmark::DoNotOptimize(registration::PrepareScan(scans.query_raw, config.reduction));
    }
    state.counters["raw_points"] = static_cast<double>(scans.query_raw.size());
}

// The query's side of the coarse search: its rotated images' spectra, once per query.
void BM_CoarseQuery(benchmark::State& state) {
    const PairScans& scans = Scans(SensorOf(state));
    const VerificationConfig config;
    for (auto _ : state) {
        benchmark::DoNotOptimize(registration::CoarseQuery(*scans.query.structure, config.coarse));
    }
}

// The candidate's side of the coarse search: one image, its correlation with every yaw.
void BM_CoarseAlign(benchmark::State& state) {
    const PairScans& scans = Scans(SensorOf(state));
    const VerificationConfig config;
    const registration::CoarseQuery coarse(*scans.query.structure, config.coarse);
    for (auto _ : state) {
        benchmark::DoNotOptimize(registration::CoarseAlign(coarse, *scans.revisit.structure));
    }
}

// Point-to-plane ICP of the true pair from the ground truth (all stages, no abandoning).
void BM_IcpFromTruth(benchmark::State& state) {
    const PairScans& scans = Scans(SensorOf(state));
    const VerificationConfig config;
    for (auto _ : state) {
        benchmark::DoNotOptimize(registration::RefinePointToPlane(
            scans.query, scans.revisit, scans.T_revisit_query, config.icp));
    }
}

void BM_MeasureOverlap(benchmark::State& state) {
    const PairScans& scans = Scans(SensorOf(state));
    const VerificationConfig config;
    for (auto _ : state) {
        benchmark::DoNotOptimize(registration::MeasureOverlap(
            scans.query, scans.revisit, scans.T_revisit_query, config.acceptance));
    }
}

// One candidate pair, coarse search included (the query's CoarseQuery is shared by its
// candidates and measured above): the figure of issue 14's < 10 ms target.
void VerifyCandidate(benchmark::State& state, const PreparedScan& candidate, bool expect_accepted) {
    const PairScans& scans = Scans(SensorOf(state));
    const VerificationConfig config;
    const registration::CoarseQuery coarse(*scans.query.structure, config.coarse);
    for (auto _ : state) {
        const auto verification = registration::Verify(scans.query, coarse, candidate, config);
        if (verification.accepted != expect_accepted) {
            state.SkipWithError(("unexpected verdict: " + ToString(verification.reason)).c_str());
            break;
        }
        benchmark::DoNotOptimize(verification);
    }
}

void BM_VerifyTrueLoop(benchmark::State& state) {
    VerifyCandidate(state, Scans(SensorOf(state)).revisit, true);
}

void BM_VerifyDifferentPlaces(benchmark::State& state) {
    VerifyCandidate(state, Scans(SensorOf(state)).elsewhere, false);
}

// Argument: the sensor's beams (64: HDL-64E, 16: VLP-16).
#define LIDARLOOP_SENSORS(bm) \
    BENCHMARK(bm)->ArgName("beams")->Arg(64)->Arg(16)->Unit(benchmark::kMillisecond)

LIDARLOOP_SENSORS(BM_PrepareScan);
LIDARLOOP_SENSORS(BM_CoarseQuery);
LIDARLOOP_SENSORS(BM_CoarseAlign);
LIDARLOOP_SENSORS(BM_IcpFromTruth);
LIDARLOOP_SENSORS(BM_MeasureOverlap);
LIDARLOOP_SENSORS(BM_VerifyTrueLoop);
LIDARLOOP_SENSORS(BM_VerifyDifferentPlaces);

}  // namespace
}  // namespace lidarloop::bench

BENCHMARK_MAIN();

// Google Benchmark of the pose-graph back end: a 5,000-pose trajectory (17 laps of an ellipse,
// drifting odometry) with 1,000 true loops, alone and with 100 wrong loops added, on one core.
// Run: ./build/bench/bench_posegraph
#include <benchmark/benchmark.h>

#include "lidarloop/eval/trajectory.hpp"
#include "lidarloop/posegraph/optimiser.hpp"
#include "posegraph/posegraph_test_utils.hpp"

namespace lidarloop::bench {
namespace {

constexpr std::size_t kPoses = 5000;
constexpr std::size_t kLoops = 1000;

struct Problem {
    std::vector<core::Transform> truth;
    std::vector<core::Transform> odometry;
    std::vector<posegraph::LoopConstraint> loops;
};

const Problem& MakeProblem() {
    static const Problem problem = [] {
        Problem p;
        p.truth = test::EllipseLaps(17);
        p.truth.resize(kPoses);
        p.odometry = test::DriftingOdometry(p.truth, 1);
        p.loops = test::TrueLoops(p.truth, 2, /*stride=*/4);
        p.loops.resize(std::min(p.loops.size(), kLoops));
        return p;
    }();
    return problem;
}

void Optimise(benchmark::State& state, std::size_t wrong_loops) {
    const Problem& p = MakeProblem();
    std::vector<posegraph::LoopConstraint> loops = p.loops;
    const auto wrong = test::WrongLoops(kPoses, wrong_loops, 3);
    loops.insert(loops.end(), wrong.begin(), wrong.end());
    const posegraph::PoseGraphConfig config;  // one thread
    const posegraph::PoseGraph graph = posegraph::BuildPoseGraph(p.odometry, loops, config);
    posegraph::OptimisationResult result;
    for (auto _ : state) {
        result = posegraph::Optimise(graph, config);
        benchmark::DoNotOptimize(result.poses.data());
    }
    state.counters["poses"] = static_cast<double>(graph.poses.size());
    state.counters["loops"] = static_cast<double>(loops.size());
    state.counters["used"] = static_cast<double>(result.loops_used);
    state.counters["rejected"] = static_cast<double>(loops.size() - result.loops_used);
    state.counters["solves"] = result.solves;
    state.counters["iterations"] = result.iterations;
    state.counters["ate_odometry_m"] = eval::AbsoluteTrajectoryRmse(p.odometry, p.truth);
    state.counters["ate_optimised_m"] = eval::AbsoluteTrajectoryRmse(result.poses, p.truth);
}

BENCHMARK_CAPTURE(Optimise, 5000_poses_1000_loops, 0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(Optimise, 5000_poses_1000_loops_100_wrong, 100)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace lidarloop::bench

BENCHMARK_MAIN();

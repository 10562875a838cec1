// lidarloop's verification and the Open3D oracle on the same scan pairs, in one process: per pair
// the time of each (thread CPU and wall), the pose of each against the ground truth, their
// difference, and lidarloop's decision. Prints one Markdown table (docs/BENCHMARK.md).
//
// Usage: verify_vs_open3d [--kitti DIR | --no-kitti] [--sim SCENE:SENSOR,...] [--steps N]
//                         [--voxel M] [--repeat N]
//   --kitti DIR   the real KITTI samples (default: ../shared/data/kitti-samples of the source tree)
//   --sim LIST    simulated U-turn drives, e.g. urban:hdl64,mine:vlp16 (default: none)
//   --steps N     azimuth steps of the simulated scans (default: the sensor's)
//   --voxel M     Open3D's global voxel grid, radii scaled as in its tutorial (default 0.75)
//   --repeat N    lidarloop runs per pair, the median time is printed (default 5); Open3D runs once
// Time a single core: OMP_NUM_THREADS=1 taskset -c 1 verify_vs_open3d ... Not installed.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "lidarloop/registration/verification.hpp"
#include "lidarloop/sim/scene.hpp"
#include "lidarloop/sim/sensor.hpp"
#include "registration/comparison_pairs.hpp"
#include "registration/open3d_oracle.hpp"

namespace {

namespace reg = lidarloop::registration;
namespace sim = lidarloop::sim;
using lidarloop::test::PairKind;
using lidarloop::test::ScanPair;

constexpr const char* kUsage =
    "usage: verify_vs_open3d [--kitti DIR | --no-kitti] [--sim SCENE:SENSOR,...] [--steps N]\n"
    "                        [--voxel M] [--repeat N]\n";

struct Options {
    std::filesystem::path kitti_dir = LIDARLOOP_KITTI_SAMPLES_DIR;
    std::vector<std::pair<sim::SceneType, sim::SensorModel>> drives;
    int steps = 0;
    int repeat = 5;
    lidarloop::test::Open3dOracleConfig open3d;
};

double ParseNumber(std::string_view flag, const char* text) {
    char* end = nullptr;
    const double value = std::strtod(text, &end);
    if (end == text || *end != '\0')
        throw std::invalid_argument(std::string(flag) + ": '" + text + "' is not a number");
    return value;
}

void ParseDrives(std::string_view list, Options& options) {
    while (!list.empty()) {
        const std::size_t comma = list.find(',');
        const std::string_view item = list.substr(0, comma);
        const std::size_t colon = item.find(':');
        if (colon == std::string_view::npos)
            throw std::invalid_argument("--sim: '" + std::string(item) + "' is not SCENE:SENSOR");
        options.drives.emplace_back(sim::ParseSceneType(item.substr(0, colon)),
                                    sim::ParseSensorModel(item.substr(colon + 1)));
        list = comma == std::string_view::npos ? std::string_view{} : list.substr(comma + 1);
    }
}

Options ParseFlags(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string_view flag = argv[i];
        if (flag == "--no-kitti") {
            options.kitti_dir.clear();
            continue;
        }
        if (i + 1 >= argc) throw std::invalid_argument(std::string(flag) + " needs a value");
        const char* value = argv[++i];
        if (flag == "--kitti") {
            options.kitti_dir = value;
        } else if (flag == "--sim") {
            ParseDrives(value, options);
        } else if (flag == "--steps") {
            options.steps = static_cast<int>(ParseNumber(flag, value));
        } else if (flag == "--repeat") {
            options.repeat = std::max(1, static_cast<int>(ParseNumber(flag, value)));
        } else if (flag == "--voxel") {
            auto& c = options.open3d;
            c.voxel_m = ParseNumber(flag, value);
            c.normal_radius_m = 2.0 * c.voxel_m;
            c.feature_radius_m = 5.0 * c.voxel_m;
            c.ransac_distance_m = 1.5 * c.voxel_m;
            c.refine_voxel_m = std::min(c.refine_voxel_m, c.voxel_m);
        } else {
            throw std::invalid_argument("unknown flag " + std::string(flag));
        }
    }
    options.open3d.Validate();
    return options;
}

// Thread CPU time and wall time of the calling thread, seconds.
struct Clock {
    static double Cpu() {
        timespec t{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
        return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
    }
    static double Wall() {
        return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
            .count();
    }
};

struct Timed {
    double cpu_ms = 0.0;
    double wall_ms = 0.0;
};

double Median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return values[values.size() / 2];
}

// lidarloop, default config: the median of `repeat` runs of each stage.
// The stages of VerifyPair: preparing both scans, the query's coarse images (once per query
// when it has several candidates), and Verify (once per candidate).
struct LidarloopTimes {
    Timed prepare, coarse, verify;
};

reg::Verification RunLidarloop(const ScanPair& pair, int repeat, LidarloopTimes& times) {
    const reg::VerificationConfig config;
    reg::Verification result;
    std::vector<double> samples[6];  // cpu and wall of each stage
    const auto lap = [&](int stage, double& cpu, double& wall) {
        samples[2 * stage].push_back(Clock::Cpu() - cpu);
        samples[2 * stage + 1].push_back(Clock::Wall() - wall);
        cpu = Clock::Cpu();
        wall = Clock::Wall();
    };
    for (int run = 0; run < repeat; ++run) {
        double cpu = Clock::Cpu(), wall = Clock::Wall();
        const reg::PreparedScan query = reg::PrepareScan(pair.query, config.reduction);
        const reg::PreparedScan match = reg::PrepareScan(pair.match, config.reduction);
        lap(0, cpu, wall);
        const reg::CoarseQuery coarse(*query.structure, config.coarse);
        lap(1, cpu, wall);
        result = reg::Verify(query, coarse, match, config);
        lap(2, cpu, wall);
    }
    Timed* stages[3] = {&times.prepare, &times.coarse, &times.verify};
    for (int stage = 0; stage < 3; ++stage)
        *stages[stage] = {1e3 * Median(samples[2 * stage]), 1e3 * Median(samples[2 * stage + 1])};
    return result;
}

void PrintRow(const ScanPair& pair, const reg::Verification& mine, const LidarloopTimes& times,
              const lidarloop::test::Open3dRegistration& theirs, const Timed& open3d) {
    using lidarloop::test::Difference;
    const auto error = [&](const lidarloop::core::Transform& T) {
        const auto d = Difference(T, pair.T_match_query_truth);
        char text[64];
        std::snprintf(text, sizeof text, "%.3f / %+.3f m, %+.2f°", d.planar_m, d.vertical_m,
                      d.yaw_deg);
        return std::string(text);
    };
    const auto between = Difference(mine.T_match_query, theirs.T_match_query);
    std::printf(
        "| %s | %s, %.1f m | %s | %.1f + %.1f + %.1f ms (%.0f + %.0f + %.0f) | %s | %.0f ms (%.0f) "
        "| %.3f | %s | %.3f m, %.2f° |\n",
        pair.name.c_str(), ToString(pair.kind), pair.T_match_query_truth.translation().norm(),
        mine.accepted ? "accept" : ("reject: " + reg::ToString(mine.reason)).c_str(),
        times.prepare.cpu_ms, times.coarse.cpu_ms, times.verify.cpu_ms, times.prepare.wall_ms,
        times.coarse.wall_ms, times.verify.wall_ms, error(mine.T_match_query).c_str(),
        open3d.cpu_ms, open3d.wall_ms, theirs.fitness, error(theirs.T_match_query).c_str(),
        between.translation_m, between.rotation_deg);
    std::fflush(stdout);
}

std::vector<ScanPair> Pairs(const Options& options) {
    std::vector<ScanPair> pairs;
    if (!options.kitti_dir.empty()) {
        pairs = lidarloop::test::KittiPairs(options.kitti_dir);
        if (pairs.empty())
            throw std::runtime_error("no KITTI samples at " + options.kitti_dir.string() +
                                     " (README.md missing); --no-kitti skips them");
    }
    for (const auto& [scene, sensor] : options.drives) {
        const sim::Simulator simulator(lidarloop::test::UTurnDrive(scene, sensor, options.steps));
        const std::string label = sim::ToString(scene) + " " + sim::ToString(sensor);
        for (ScanPair& pair : lidarloop::test::SimulatedPairs(simulator, label))
            pairs.push_back(std::move(pair));
    }
    return pairs;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const Options options = ParseFlags(argc, argv);
        const std::vector<ScanPair> pairs = Pairs(options);
        std::printf(
            "| pair (query->match) | kind, apart | lidarloop | lidarloop CPU: prepare 2 scans + "
            "coarse images + Verify (wall) | "
            "lidarloop vs truth: planar / vertical, yaw | Open3D CPU (wall) | Open3D fitness | "
            "Open3D vs truth | lidarloop vs Open3D |\n|---|---|---|---|---|---|---|---|---|\n");
        for (const ScanPair& pair : pairs) {
            LidarloopTimes times;
            Timed open3d;
            const reg::Verification mine = RunLidarloop(pair, options.repeat, times);
            const double cpu = Clock::Cpu(), wall = Clock::Wall();
            const auto theirs =
                lidarloop::test::RegisterWithOpen3d(pair.query, pair.match, options.open3d);
            open3d = {1e3 * (Clock::Cpu() - cpu), 1e3 * (Clock::Wall() - wall)};
            PrintRow(pair, mine, times, theirs, open3d);
        }
    } catch (const std::exception& error) {
        std::fprintf(stderr, "verify_vs_open3d: %s\n%s", error.what(), kUsage);
        return 1;
    }
    return 0;
}

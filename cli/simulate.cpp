#include <atomic>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/kitti_sequence.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/sim/simulator.hpp"
#include "progress.hpp"
#include "simulate.hpp"

namespace lidarloop::cli {
namespace {

constexpr std::size_t kPoseChunk = 4096;
constexpr double kRevisitDistance_m = 4.0;  // catches lane-offset revisits (3.5 m in town)
constexpr std::size_t kRevisitGap = 30;

struct SimulateFlags {
    std::string scene = "urban";
    std::string route = "uturn";
    std::string sensor = "hdl64";
    long long scans = 100;
    std::uint64_t seed = 1;
    std::string out;
    double noise_m = sim::SensorConfig{}.noise_m;
    double dropout = sim::SensorConfig{}.dropout;
    double drift = 1.0;
    int threads = 0;
    bool overwrite = false;
    bool quiet = false;
    // Flags whose default is the sensor model's or the route's value: set only when given.
    std::optional<double> min_range_m;
    std::optional<double> max_range_m;
    std::optional<double> mount_height_m;
    std::optional<int> horizontal_steps;
    std::optional<double> spacing_min_m;
    std::optional<double> spacing_max_m;
    std::optional<int> uturn_blocks;
};

sim::SimulationConfig ToConfig(const SimulateFlags& flags) {
    sim::SimulationConfig config;
    config.scene = sim::ParseSceneType(flags.scene);
    config.route.type = sim::ParseRouteType(flags.route);
    config.sensor.model = sim::ParseSensorModel(flags.sensor);
    if (flags.scans < 1 || flags.scans > 1'000'000) {
        throw core::ConfigError("--scans must be in [1, 1000000], got " +
                                std::to_string(flags.scans));
    }
    if (!(flags.drift >= 0.0)) {
        throw core::ConfigError("--drift must be >= 0 (a factor on the default odometry noise)");
    }
    config.scans = static_cast<std::size_t>(flags.scans);
    config.seed = flags.seed;
    config.sensor.noise_m = flags.noise_m;
    config.sensor.dropout = flags.dropout;
    config.sensor.min_range_m = flags.min_range_m;
    config.sensor.max_range_m = flags.max_range_m;
    config.sensor.mount_height_m = flags.mount_height_m;
    config.sensor.horizontal_steps = flags.horizontal_steps;
    config.route.spacing_min_m = flags.spacing_min_m.value_or(config.route.spacing_min_m);
    config.route.spacing_max_m = flags.spacing_max_m.value_or(config.route.spacing_max_m);
    config.route.uturn_blocks = flags.uturn_blocks.value_or(config.route.uturn_blocks);
    config.odometry.yaw_noise_deg *= flags.drift;
    config.odometry.translation_noise *= flags.drift;
    config.Validate();
    return config;
}

std::string Number(double value) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return std::string(buffer, result.ptr);
}

// The effective parameters, so that a sequence can be made again and its origin is known.
void WriteSimulationYaml(const std::filesystem::path& file, const sim::Simulator& simulator) {
    const sim::SimulationConfig& c = simulator.config();
    const sim::SensorSpec& s = simulator.sensor();
    std::ofstream out(file);
    out << "# lidarloop " << LIDARLOOP_VERSION << " simulate: the parameters of this sequence\n"
        << "scene: " << sim::ToString(c.scene) << "\n"
        << "scans: " << c.scans << "\n"
        << "seed: " << c.seed << "\n"
        << "route:\n"
        << "  type: " << sim::ToString(c.route.type) << "\n"
        << "  spacing_min_m: " << Number(c.route.spacing_min_m) << "\n"
        << "  spacing_max_m: " << Number(c.route.spacing_max_m) << "\n"
        << "  uturn_blocks: " << c.route.uturn_blocks << "\n"
        << "  lap_length_m: " << Number(simulator.route().lap_length_m()) << "\n"
        << "sensor:\n"
        << "  model: " << sim::ToString(s.model) << "\n"
        << "  beams: " << s.beams << "\n"
        << "  horizontal_steps: " << s.horizontal_steps << "\n"
        << "  min_range_m: " << Number(s.min_range_m) << "\n"
        << "  max_range_m: " << Number(s.max_range_m) << "\n"
        << "  mount_height_m: " << Number(s.mount_height_m) << "\n"
        << "  scan_period_s: " << Number(s.scan_period_s) << "\n"
        << "  noise_m: " << Number(s.noise_m) << "\n"
        << "  dropout: " << Number(s.dropout) << "\n"
        << "odometry:\n"
        << "  yaw_noise_deg: " << Number(c.odometry.yaw_noise_deg) << "\n"
        << "  translation_noise: " << Number(c.odometry.translation_noise) << "\n"
        << "files:\n"
        << "  scans: velodyne/NNNNNN.bin  # KITTI float32 x y z intensity(0), sensor frame\n"
        << "  poses: poses.txt  # ground truth T_world_sensor, 3x4 row-major, LiDAR frame\n"
        << "  odometry: poses_odometry.txt  # the same with accumulated drift\n"
        << "  times: times.txt  # seconds\n";
    out.close();
    if (!out) throw io::WriteError(file, "writing failed");
}

struct ScanStats {
    std::atomic<std::size_t> points{0};
    std::atomic<std::size_t> min_points{std::numeric_limits<std::size_t>::max()};
    std::atomic<std::size_t> max_points{0};
    std::atomic<std::size_t> done{0};

    void Add(std::size_t count) {
        points += count;
        std::size_t seen = min_points.load();
        while (count < seen && !min_points.compare_exchange_weak(seen, count)) {
        }
        seen = max_points.load();
        while (count > seen && !max_points.compare_exchange_weak(seen, count)) {
        }
        ++done;
    }
};

void WriteScans(const sim::Simulator& simulator, const io::KittiSequenceWriter& writer, int threads,
                bool quiet, ScanStats& stats) {
    ProgressBar progress("simulate", quiet);
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, simulator.size(), 1),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t i = range.begin(); i < range.end(); ++i) {
                                  const core::PointCloud cloud = simulator.Scan(i);
                                  writer.WriteScan(i, cloud);
                                  stats.Add(cloud.size());
                                  progress.Update(stats.done, simulator.size());
                              }
                          });
    });
}

void WritePoses(const sim::Simulator& simulator, io::KittiSequenceWriter& writer) {
    for (std::size_t first = 0; first < simulator.size(); first += kPoseChunk) {
        const std::size_t count = std::min(kPoseChunk, simulator.size() - first);
        const std::vector<core::StampedPose> odometry = simulator.OdometryPoses(first, count);
        for (std::size_t k = 0; k < count; ++k) {
            writer.AppendPose(simulator.GroundTruthPose(first + k));
            writer.AppendOdometryPose(odometry[k]);
        }
    }
    writer.Finish();
}

void RunSimulate(const SimulateFlags& flags) {
    const sim::Simulator simulator(ToConfig(flags));
    const SimulationSummary summary =
        WriteSimulation(simulator, flags.out, flags.overwrite, flags.threads, flags.quiet);
    const sim::SimulationConfig& c = simulator.config();
    char timing[32];
    std::snprintf(timing, sizeof(timing), "%.2f s", summary.seconds);
    std::cout << "simulated " << c.scans << " scans (" << sim::ToString(c.scene) << ", "
              << sim::ToString(c.route.type) << ", " << sim::ToString(c.sensor.model) << ", seed "
              << c.seed << ") into " << flags.out << ": " << summary.mean_points
              << " points per scan (min " << summary.min_points << ", max " << summary.max_points
              << "), " << summary.revisited_scans << " scans revisit a place (within "
              << Number(kRevisitDistance_m) << " m of a scan " << kRevisitGap << "+ earlier), "
              << timing << "\n";
}

}  // namespace

SimulationSummary WriteSimulation(const sim::Simulator& simulator, const std::filesystem::path& out,
                                  bool overwrite, int threads, bool quiet) {
    const auto start = std::chrono::steady_clock::now();
    io::KittiSequenceWriter writer(out, overwrite);
    ScanStats stats;
    WriteScans(simulator, writer, threads, quiet, stats);
    WritePoses(simulator, writer);
    WriteSimulationYaml(writer.dir() / "simulation.yaml", simulator);
    SimulationSummary summary;
    summary.mean_points = stats.points / simulator.size();
    summary.min_points = stats.min_points;
    summary.max_points = stats.max_points;
    summary.revisited_scans = sim::CountRevisitedScans(simulator, kRevisitGap, kRevisitDistance_m);
    summary.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return summary;
}

void AddSimulateCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "simulate", "Write a synthetic LiDAR sequence with revisits in the KITTI odometry layout");
    auto flags = std::make_shared<SimulateFlags>();
    command->add_option("--scene", flags->scene, "urban, rural, mine or indoor")
        ->capture_default_str();
    command->add_option("--route", flags->route, "uturn, figure8 or grid")->capture_default_str();
    command->add_option("--sensor", flags->sensor, "hdl64, vlp16 or tilt180")
        ->capture_default_str();
    command->add_option("--scans", flags->scans, "number of scans, 1-1000000")
        ->capture_default_str();
    command->add_option("--seed", flags->seed, "seed of world, speed, noise and drift")
        ->capture_default_str();
    command->add_option("--out", flags->out, "output folder (velodyne/, poses.txt, times.txt)")
        ->required();
    command->add_option("--noise-m", flags->noise_m, "sigma of the range noise, metres")
        ->capture_default_str();
    command->add_option("--dropout", flags->dropout, "probability of a lost return, [0, 1)")
        ->capture_default_str();
    command->add_option("--min-range-m", flags->min_range_m, "default: the sensor's");
    command->add_option("--max-range-m", flags->max_range_m, "default: the sensor's");
    command->add_option("--mount-height-m", flags->mount_height_m,
                        "sensor height above the ground; default: the sensor's");
    command->add_option("--horizontal-steps", flags->horizontal_steps,
                        "azimuth steps per revolution (hdl64 1875, vlp16 1800) or samples per "
                        "line (tilt180 361); fewer for smaller files");
    command->add_option("--spacing-min-m", flags->spacing_min_m, "default 1");
    command->add_option("--spacing-max-m", flags->spacing_max_m, "default 2");
    command->add_option("--uturn-blocks", flags->uturn_blocks,
                        "street length of the uturn route in blocks; default: from --scans");
    command
        ->add_option("--drift", flags->drift,
                     "factor on the odometry noise (0: odometry = ground truth)")
        ->capture_default_str();
    command->add_option("--threads", flags->threads, "worker threads; 0: all cores")
        ->capture_default_str();
    command->add_flag("--overwrite", flags->overwrite, "replace the scans of an earlier run");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunSimulate(*flags); });
}

}  // namespace lidarloop::cli

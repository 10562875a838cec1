#include <charconv>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "lidarloop/app/simulation.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/sim/odometry_drift.hpp"
#include "progress.hpp"
#include "run_output.hpp"

namespace lidarloop::cli {
namespace {

struct SimulateFlags {
    std::string scene = "urban";
    std::string route = "uturn";
    std::string sensor = "hdl64";
    long long scans = 100;
    std::uint64_t seed = 1;
    std::string out;
    std::string trajectory;  // KITTI or TUM poses to drive instead of the route
    double noise_m = sim::SensorConfig{}.noise_m;
    double dropout = sim::SensorConfig{}.dropout;
    double drift = 1.0;
    std::int64_t keep_every = sim::FrontEndConfig{}.keep_every;
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
    config.scans = static_cast<std::size_t>(flags.scans);
    if (!flags.trajectory.empty()) {
        for (const core::StampedPose& pose : io::ReadPoses(flags.trajectory)) {
            config.trajectory.push_back(pose.T_world_sensor.translation());
        }
        if (config.trajectory.empty())
            throw io::ReadError(flags.trajectory, "holds no poses: nothing to drive");
        try {
            sim::PlanarTrajectory(config.trajectory);  // its checks, with the file named
        } catch (const core::ConfigError& error) {
            throw io::ReadError(flags.trajectory, error.what());
        }
        config.scans = config.trajectory.size();
    }
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
    config.odometry = sim::ScaledOdometry(config.odometry, flags.drift);
    config.front_end.keep_every = flags.keep_every;
    config.Validate();
    return config;
}

std::string Number(double value) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return std::string(buffer, result.ptr);
}

void RunSimulate(const SimulateFlags& flags) {
    const sim::Simulator simulator(ToConfig(flags));
    ProgressPrinter progress(flags.quiet);
    const app::SimulationSummary summary =
        app::WriteSimulation(simulator, flags.out, CommandRun({flags.trajectory}, flags.overwrite),
                             flags.threads, progress.Callback());
    const sim::SimulationConfig& c = simulator.config();
    char timing[32];
    std::snprintf(timing, sizeof(timing), "%.2f s", summary.seconds);
    std::cout << "simulated " << c.scans << " scans (" << sim::ToString(c.scene) << ", "
              << (c.trajectory.empty() ? sim::ToString(c.route.type)
                                       : "trajectory " + flags.trajectory)
              << ", " << sim::ToString(c.sensor.model) << ", seed " << c.seed << ") into "
              << flags.out << ": " << summary.mean_points << " points per scan (min "
              << summary.min_points << ", max " << summary.max_points << "), "
              << summary.revisited_scans << " scans revisit a place (within "
              << Number(app::kRevisitDistance_m) << " m of a scan " << app::kRevisitGap
              << "+ earlier), " << timing << "\n";
}

}  // namespace

void AddSimulateCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "simulate", "Write a synthetic LiDAR sequence with revisits in the KITTI odometry layout");
    auto flags = std::make_shared<SimulateFlags>();
    command->add_option("--scene", flags->scene, "urban, rural, mine or indoor")
        ->capture_default_str();
    command->add_option("--route", flags->route, "uturn, figure8 or grid")->capture_default_str();
    command
        ->add_option("--sensor", flags->sensor,
                     "hdl64, vlp16, tilt180, hdl32, ouster64-wide or livox-avia")
        ->capture_default_str();
    command->add_option("--scans", flags->scans, "number of scans, 1-1000000")
        ->capture_default_str();
    command
        ->add_option("--trajectory", flags->trajectory,
                     "drive this trajectory (KITTI 3x4 or TUM poses; positions only, one scan "
                     "per pose, --scans ignored) through the scene instead of --route")
        ->check(CLI::ExistingFile);
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
                        "azimuth steps per revolution (hdl64 1875, vlp16 1800, hdl32 2170, "
                        "ouster64-wide 1024), samples per line (tilt180 361) or per laser "
                        "(livox-avia 4000); fewer for smaller files");
    command
        ->add_option("--keep-every", flags->keep_every,
                     "keep every N-th returned point of each scan, as a LIO front end thins "
                     "its keyframes, 1-1000")
        ->capture_default_str();
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
    command->add_flag("--overwrite", flags->overwrite,
                      "write into a non-empty folder that holds no lidarloop sequence, replacing "
                      "its files of the same names");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunSimulate(*flags); });
}

}  // namespace lidarloop::cli

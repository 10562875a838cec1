#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "dataset_options.hpp"
#include "lidarloop/app/map_building.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "progress.hpp"
#include "run_output.hpp"

namespace lidarloop::cli {
namespace {

struct MapFlags {
    DatasetOptions dataset;
    std::string poses;
    std::string calib;  // converts --poses from KITTI's camera frame
    std::string out;
    std::string config;
    std::optional<double> voxel_m;          // map.voxel_m when given
    std::optional<std::size_t> max_points;  // map.max_points when given
    bool overwrite = false;
    bool quiet = false;
};

void RunMapCommand(const MapFlags& flags) {
    ProgressPrinter progress(flags.quiet);
    io::RunConfig config =
        flags.config.empty() ? io::RunConfig{} : io::LoadConfigYaml(flags.config);
    if (flags.voxel_m) config.map.voxel_m = *flags.voxel_m;
    if (flags.max_points) config.map.max_points = *flags.max_points;
    app::MapRequest request;
    request.poses_file = flags.poses;
    request.calib_file = flags.calib;
    request.config = config.map;
    request.out = flags.out;
    request.inputs = flags.dataset.Inputs();
    request.inputs.emplace_back(flags.config);
    request.overwrite = flags.overwrite;
    request.progress = progress.Callback();
    const io::Dataset dataset = flags.dataset.Open();
    const app::MapOutcome outcome = app::RunMap(dataset, request);
    char seconds[32];
    std::snprintf(seconds, sizeof(seconds), "%.2f", outcome.total_s);
    std::cout << "lidarloop map: " << outcome.scans << " scans, " << outcome.input_points
              << " points -> " << outcome.points << " points in voxels of " << outcome.voxel_m
              << " m (" << seconds << " s): " << request.out.string() << "\n";
    for (const std::string& note : outcome.notes) std::cout << "  note: " << note << "\n";
}

}  // namespace

void AddMapCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "map", "Place every scan with a trajectory into one voxel-downsampled map (PLY)");
    auto flags = std::make_shared<MapFlags>();
    flags->dataset.AddTo(*command, "--format", /*with_poses=*/false);
    command
        ->add_option("--poses", flags->poses,
                     "trajectory, KITTI or TUM, one T_world_sensor per scan (as optimise's "
                     "--odometry and poses_optimised.txt); default: the dataset's poses")
        ->check(CLI::ExistingFile);
    command
        ->add_option("--calib", flags->calib,
                     "KITTI calib.txt whose Tr converts --poses from KITTI's camera frame to the "
                     "LiDAR frame (KITTI's official poses are in the camera frame)")
        ->check(CLI::ExistingFile);
    command->add_option("--out", flags->out, "PLY file to write (binary, coloured by scan time)")
        ->required();
    command->add_option("--config", flags->config, "YAML file; its map.* keys apply")
        ->check(CLI::ExistingFile);
    // No CLI11 check: MapConfig::Validate names the key and range ("map.voxel_m must be in ...").
    command->add_option("--voxel", flags->voxel_m,
                        "M: voxel edge, [0.01, 100]; map.voxel_m, default 0.2");
    command->add_option("--max-points", flags->max_points,
                        "N: most points, [1000, 1e8]; a larger map gets coarser voxels; "
                        "map.max_points, default 2000000");
    command->add_flag("--overwrite", flags->overwrite,
                      "replace --out also when it is not a PLY file that lidarloop wrote");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunMapCommand(*flags); });
}

}  // namespace lidarloop::cli

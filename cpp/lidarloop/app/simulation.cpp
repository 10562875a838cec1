#include "lidarloop/app/simulation.hpp"

#include <atomic>
#include <chrono>
#include <fstream>
#include <limits>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/io/kitti_sequence.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/run_record.hpp"

namespace lidarloop::app {
namespace {

constexpr std::size_t kPoseChunk = 4096;

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
        << "  spacing_min_m: " << core::NumberText(c.route.spacing_min_m) << "\n"
        << "  spacing_max_m: " << core::NumberText(c.route.spacing_max_m) << "\n"
        << "  uturn_blocks: " << c.route.uturn_blocks << "\n"
        << "  lap_length_m: " << core::NumberText(simulator.route().lap_length_m()) << "\n"
        << "trajectory_poses: " << c.trajectory.size()
        << "  # > 0: a given trajectory, not the route\n"
        << "sensor:\n"
        << "  model: " << sim::ToString(s.model) << "\n"
        << "  beams: " << s.beams << "\n"
        << "  horizontal_steps: " << s.horizontal_steps << "\n"
        << "  min_range_m: " << core::NumberText(s.min_range_m) << "\n"
        << "  max_range_m: " << core::NumberText(s.max_range_m) << "\n"
        << "  mount_height_m: " << core::NumberText(s.mount_height_m) << "\n"
        << "  scan_period_s: " << core::NumberText(s.scan_period_s) << "\n"
        << "  noise_m: " << core::NumberText(s.noise_m) << "\n"
        << "  dropout: " << core::NumberText(s.dropout) << "\n"
        << "front_end:\n"
        << "  keep_every: " << c.front_end.keep_every
        << "  # every N-th returned point of a scan kept\n"
        << "odometry:\n"
        << "  yaw_noise_deg: " << core::NumberText(c.odometry.yaw_noise_deg) << "\n"
        << "  translation_noise: " << core::NumberText(c.odometry.translation_noise) << "\n"
        << "  yaw_bias_deg_per_100m: " << core::NumberText(c.odometry.yaw_bias_deg_per_100m) << "\n"
        << "  length_bias: " << core::NumberText(c.odometry.length_bias) << "\n"
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

    void Add(std::size_t count) {
        points += count;
        std::size_t seen = min_points.load();
        while (count < seen && !min_points.compare_exchange_weak(seen, count)) {
        }
        seen = max_points.load();
        while (count > seen && !max_points.compare_exchange_weak(seen, count)) {
        }
    }
};

void WriteScans(const sim::Simulator& simulator, const io::KittiSequenceWriter& writer, int threads,
                const Progress& progress, ScanStats& stats) {
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    pipeline::ProgressCounter done(StageReport(progress, "simulate"), simulator.size());
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, simulator.size(), 1),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t i = range.begin(); i < range.end(); ++i) {
                                  const core::PointCloud cloud = simulator.Scan(i);
                                  writer.WriteScan(i, cloud);
                                  stats.Add(cloud.size());
                                  done.Add();
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

}  // namespace

SimulationSummary WriteSimulation(const sim::Simulator& simulator, const std::filesystem::path& out,
                                  RunInfo run, int threads, const Progress& progress) {
    if (threads < 0) {
        throw core::ConfigError("threads must be 0 (all cores) or more, got " +
                                std::to_string(threads));
    }
    const auto start = std::chrono::steady_clock::now();
    run.kind = io::RunKind::kDataset;
    ScanStats stats;
    RunInFolder(out, std::move(run), [&](const std::filesystem::path& staging) {
        io::KittiSequenceWriter writer(staging);
        WriteScans(simulator, writer, threads, progress, stats);
        WritePoses(simulator, writer);
        WriteSimulationYaml(staging / "simulation.yaml", simulator);
        return 0;
    });
    SimulationSummary summary;
    summary.mean_points = stats.points / simulator.size();
    summary.min_points = stats.min_points;
    summary.max_points = stats.max_points;
    summary.revisited_scans = sim::CountRevisitedScans(simulator, kRevisitGap, kRevisitDistance_m);
    summary.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return summary;
}

DemoSequence PrepareDemoSequence(const std::filesystem::path& folder, RunInfo run,
                                 const Progress& progress) {
    DemoSequence demo{folder, std::nullopt};
    const std::optional<io::RunRecord> record = io::ReadRunRecord(folder);
    if (record && record->kind == io::RunKind::kDataset && record->status == "complete" &&
        std::filesystem::exists(folder / "simulation.yaml")) {
        return demo;
    }
    const sim::Simulator simulator(sim::DemoConfig());
    demo.generated = WriteSimulation(simulator, folder, std::move(run), /*threads=*/0, progress);
    return demo;
}

}  // namespace lidarloop::app

#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/sim/front_end.hpp"
#include "lidarloop/sim/odometry.hpp"
#include "lidarloop/sim/route.hpp"
#include "lidarloop/sim/scene.hpp"
#include "lidarloop/sim/sensor.hpp"
#include "lidarloop/sim/world.hpp"

namespace lidarloop::sim {

/// Everything that determines a simulated sequence. Same config, same sequence, byte for byte
/// (on the same platform: the C library's sin, cos and log are part of the computation).
struct SimulationConfig {
    SceneType scene = SceneType::kUrban;
    RouteConfig route;
    SensorConfig sensor;
    OdometryConfig odometry;
    FrontEndConfig front_end;  ///< the thinning of each scan, after the sensor's dropouts
    std::size_t scans = 100;   ///< number of scans, [1, 1e6]
    std::uint64_t seed = 1;    ///< one seed for world, speed profile, noise and drift
    /// A given trajectory to drive instead of the route (one pose per scan, so `scans` must equal
    /// its size): only the positions are used, projected onto their best-fit plane (so KITTI's
    /// camera-frame poses work as they are); the heading follows the direction of travel, and
    /// the vehicle stands on the scene's ground. The scene is generated over the streets
    /// around the trajectory, and every object within the road half width of its path is left
    /// out, so that the vehicle drives through the world as through streets. Empty: the route.
    std::vector<Eigen::Vector3d> trajectory;

    /// Throws core::ConfigError naming the first invalid field ("scans must be ...").
    void Validate() const;
};

/// A synthetic LiDAR sequence computed on demand: a seeded world, a route through it with
/// ground-truth poses, a drifting odometry, and scans ray cast from the ground-truth poses.
/// Nothing is stored per scan, so sequences of any length stream through constant memory.
///
/// Frames: the world frame has z up; T_world_sensor of scan i puts the sensor mount_height_m
/// above the ground along the ground's normal, x along the direction of travel (following the
/// slope), z along the normal. Scans are in the sensor frame (x forward, y left, z up), metres;
/// points with no return (nothing within range, or a dropout) are left out, not stored as NaN.
/// Time of scan i: i * scan_period_s.
///
/// Every member function is const and thread-safe; Scan(i) depends only on (config, i), so scans
/// may be generated in any order and in parallel.
class Simulator {
public:
    /// Validates the config (throws core::ConfigError) and builds the world around the route.
    explicit Simulator(const SimulationConfig& config);

    std::size_t size() const { return config_.scans; }
    /// The effective config: the given one with the sensor's model values and the U-turn length
    /// filled in, so that Simulator(simulator.config()) makes the same sequence.
    const SimulationConfig& config() const { return config_; }
    const SensorSpec& sensor() const { return sensor_; }
    const SceneLayout& layout() const { return layout_; }
    const RoutePath& route() const { return route_; }
    const World& world() const { return world_; }
    /// Unit ray directions of scan 0 in the sensor frame (see BeamDirections); those of every
    /// scan when RepeatsEveryScan(sensor().model).
    const std::vector<Eigen::Vector3d>& beam_directions() const { return directions_; }
    /// Unit ray directions of scan `index` in the sensor frame, in the sensor's order.
    std::vector<Eigen::Vector3d> ScanDirections(std::size_t index) const;

    /// Ground truth T_world_sensor of scan `index` (< size(), else std::out_of_range).
    core::StampedPose GroundTruthPose(std::size_t index) const;
    /// The drifting odometry's T_world_sensor of scan `index`; equals the ground truth at 0.
    /// O(256) (it replays the measured steps from the last stored checkpoint).
    core::StampedPose OdometryPose(std::size_t index) const;
    /// OdometryPose of scans first .. first + count - 1 in one pass (first + count <= size()).
    std::vector<core::StampedPose> OdometryPoses(std::size_t first, std::size_t count) const;
    /// The scan taken at GroundTruthPose(index): ray cast along ScanDirections(index), then
    /// dropouts and range noise drawn from a generator seeded by (seed, index), then thinned
    /// as config().front_end says (so a thinned scan holds exactly every N-th point of the
    /// unthinned one).
    core::PointCloud Scan(std::size_t index) const;

private:
    void CheckIndex(std::size_t index) const;
    RoutePoint PointAt(std::size_t index) const;

    SimulationConfig config_;
    SensorSpec sensor_;
    SceneLayout layout_;
    SpacingProfile spacing_;
    RoutePath route_;
    World world_;
    std::vector<Eigen::Vector3d> directions_;
    std::vector<core::Transform> odometry_checkpoints_;  // every kCheckpointStride scans
    std::vector<RoutePoint> trajectory_;  // config_.trajectory in the plane; empty: the route
};

/// The longest path of a given trajectory, metres: the world is generated over its bounding box
/// and the path sampled every metre (1,000 km took 1 GB), and a day's drive is 200 km.
inline constexpr double kMaxTrajectoryPathM = 200'000.0;

/// The points of a given trajectory in its best-fit plane: positions projected onto the two
/// directions of largest spread, relative to the first position, seen from "up": the plane's
/// normal on the side of the input's +z, or of its -y when z lies in the plane (a camera frame,
/// y down, as KITTI's poses); heading along the direction of travel (central differences; a stop
/// keeps the last heading). Throws core::ConfigError for fewer than 2 positions, all within
/// 1 m of each other, a non-finite one, or a path longer than kMaxTrajectoryPathM.
std::vector<RoutePoint> PlanarTrajectory(const std::vector<Eigen::Vector3d>& positions);

/// The world of `type` generated over the streets around `path` with every object whose
/// footprint comes within `clearance_m` of the path (sampled every metre) left out.
World WorldAroundPath(SceneType type, std::uint64_t seed, const std::vector<RoutePoint>& path,
                      double clearance_m);

/// How often a place is visited again: the number of scans i that have an earlier scan j with
/// i - j >= min_index_gap whose ground-truth position is within max_distance_m. O(n) with a
/// hash grid. Loops "by construction" for a summary; evaluation has its own ground truth.
std::size_t CountRevisitedScans(const Simulator& simulator, std::size_t min_index_gap = 30,
                                double max_distance_m = 3.0);

/// The sequence of `lidarloop demo`: 320 keyframes, 0.25 s and 2.5-3.5 m apart, of a VLP-16 at
/// reduced resolution (16 x 256 rays, about 3600 points) on the grid route through the urban
/// scene: nearly one lap, with revisits in the same lane, in the opposite direction and a lane
/// to the side, and crossings; 16 x 1024 rays per scan (~14k points). About 70 MB in the
/// KITTI layout, generated in about a second on 2 cores (so it is made, not bundled).
SimulationConfig DemoConfig();

}  // namespace lidarloop::sim

#include "lidarloop/sim/simulator.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

#include <Eigen/Eigenvalues>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/sim/detail/random.hpp"

namespace lidarloop::sim {
namespace {

constexpr std::size_t kMaxScans = 1'000'000;
constexpr std::size_t kCheckpointStride = 256;
constexpr int kMaxAutoUturnBlocks = 12;

// The sensor pose of a vehicle standing on the ground at `point`: x along the direction of travel
// following the slope, z along the ground normal, the sensor mount_height_m up that normal.
core::Transform VehiclePose(const RoutePoint& point, const Terrain& ground, double mount_height_m) {
    const double x = point.position_m.x();
    const double y = point.position_m.y();
    const Eigen::Vector2d g = ground.Gradient(x, y);
    const Eigen::Vector3d normal = Eigen::Vector3d(-g.x(), -g.y(), 1.0).normalized();
    const Eigen::Vector2d heading(std::cos(point.heading_rad), std::sin(point.heading_rad));
    const Eigen::Vector3d forward_guess(heading.x(), heading.y(), g.dot(heading));
    const Eigen::Vector3d left = normal.cross(forward_guess).normalized();
    const Eigen::Vector3d forward = left.cross(normal);
    core::Transform T_world_sensor = core::Transform::Identity();
    T_world_sensor.linear().col(0) = forward;
    T_world_sensor.linear().col(1) = left;
    T_world_sensor.linear().col(2) = normal;
    T_world_sensor.translation() =
        Eigen::Vector3d(x, y, ground.Height(x, y)) + mount_height_m * normal;
    return T_world_sensor;
}

int UturnBlocks(const SimulationConfig& config, const SceneLayout& layout) {
    if (config.route.uturn_blocks > 0) return config.route.uturn_blocks;
    // One out-and-back within the sequence, so that the way home revisits the way out.
    const double mean_spacing = 0.5 * (config.route.spacing_min_m + config.route.spacing_max_m);
    const double length_m = static_cast<double>(config.scans) * mean_spacing;
    const int blocks = static_cast<int>(length_m / (2.0 * layout.block_pitch_m));
    return std::clamp(blocks, 1, kMaxAutoUturnBlocks);
}

NodeRange Grow(NodeRange nodes, int margin) {
    return {nodes.i_min - margin, nodes.i_max + margin, nodes.j_min - margin, nodes.j_max + margin};
}

SensorSpec ResolveFor(const SimulationConfig& config, const SceneLayout& layout) {
    config.Validate();
    SensorSpec spec = Resolve(config.sensor);
    if (layout.ceiling_height_m > 0.0 && spec.mount_height_m > layout.ceiling_height_m - 0.2) {
        throw core::ConfigError("sensor.mount_height_m " + core::NumberText(spec.mount_height_m) +
                                " m does not fit under the " +
                                core::NumberText(layout.ceiling_height_m) + " m ceiling of the " +
                                ToString(config.scene) + " scene");
    }
    return spec;
}

// The world of a sequence: around the route's streets, or around the given trajectory.
World MakeWorld(const SimulationConfig& config, const SceneLayout& layout, const RoutePath& route,
                const std::vector<RoutePoint>& trajectory) {
    if (trajectory.empty()) {
        return GenerateWorld(config.scene, config.seed, Grow(route.VisitedNodes(), 1));
    }
    return WorldAroundPath(config.scene, config.seed, trajectory, layout.road_half_width_m);
}

// The unit normal of the best-fit plane of `centred` positions, on the side of "up".
Eigen::Vector3d PlaneNormal(const std::vector<Eigen::Vector3d>& centred) {
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const auto& p : centred) scatter += p * p.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
    Eigen::Vector3d normal = eigen.eigenvectors().col(0);  // smallest spread
    const Eigen::Vector3d up =
        std::abs(normal.z()) > 0.5 ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d(0, -1, 0);
    return normal.dot(up) < 0.0 ? Eigen::Vector3d(-normal) : normal;
}

}  // namespace

std::vector<RoutePoint> PlanarTrajectory(const std::vector<Eigen::Vector3d>& positions) {
    if (positions.size() < 2) {
        throw core::ConfigError("a trajectory needs at least 2 poses, got " +
                                std::to_string(positions.size()));
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : positions) {
        if (!p.allFinite()) throw core::ConfigError("a trajectory position is not finite");
        mean += p;
    }
    mean /= static_cast<double>(positions.size());
    std::vector<Eigen::Vector3d> centred;
    double spread = 0.0;
    for (const auto& p : positions) {
        centred.push_back(p - mean);
        spread = std::max(spread, (p - positions.front()).norm());
    }
    if (spread < 1.0) throw core::ConfigError("the trajectory stays within 1 m: nothing to drive");
    double path_m = 0.0;
    for (std::size_t i = 1; i < positions.size(); ++i)
        path_m += (positions[i] - positions[i - 1]).norm();
    if (path_m > kMaxTrajectoryPathM) {
        throw core::ConfigError(
            "the trajectory's path is " + core::NumberText(std::round(path_m / 1000.0)) +
            " km long, more than the " + core::NumberText(kMaxTrajectoryPathM / 1000.0) +
            " km a simulated world is made for (a jump in the poses?)");
    }
    const Eigen::Vector3d normal = PlaneNormal(centred);
    const Eigen::Vector3d e1 = normal.unitOrthogonal();
    const Eigen::Vector3d e2 = normal.cross(e1);
    std::vector<RoutePoint> points(positions.size());
    for (std::size_t i = 0; i < positions.size(); ++i) {
        const Eigen::Vector3d d = positions[i] - positions.front();
        points[i].position_m = Eigen::Vector2d(d.dot(e1), d.dot(e2));
    }
    double heading = 0.0;
    std::size_t first_move = points.size();
    for (std::size_t i = 0; i < points.size(); ++i) {
        const std::size_t before = i > 0 ? i - 1 : 0;
        const std::size_t after = std::min(i + 1, points.size() - 1);
        const Eigen::Vector2d step = points[after].position_m - points[before].position_m;
        if (step.norm() > 1e-3) {
            heading = std::atan2(step.y(), step.x());
            first_move = std::min(first_move, i);
        }
        points[i].heading_rad = heading;
    }
    // A stop at the start faces where the vehicle goes first.
    for (std::size_t i = 0; i < first_move && first_move < points.size(); ++i) {
        points[i].heading_rad = points[first_move].heading_rad;
    }
    return points;
}

World WorldAroundPath(SceneType type, std::uint64_t seed, const std::vector<RoutePoint>& path,
                      double clearance_m) {
    const SceneLayout layout = LayoutOf(type);
    // Path samples every metre, in a hash grid of cells of the clearance.
    std::vector<Eigen::Vector2d> samples;
    for (std::size_t i = 0; i + 1 < path.size(); ++i) {
        const Eigen::Vector2d a = path[i].position_m;
        const Eigen::Vector2d b = path[i + 1].position_m;
        const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm())));
        for (int k = 0; k < steps; ++k)
            samples.push_back(a + (b - a) * (k / static_cast<double>(steps)));
    }
    samples.push_back(path.back().position_m);
    Eigen::Vector2d low = samples.front(), high = samples.front();
    for (const auto& p : samples) {
        low = low.cwiseMin(p);
        high = high.cwiseMax(p);
    }
    const double pitch = layout.block_pitch_m;
    const NodeRange nodes{static_cast<int>(std::floor(low.x() / pitch)) - 1,
                          static_cast<int>(std::ceil(high.x() / pitch)) + 1,
                          static_cast<int>(std::floor(low.y() / pitch)) - 1,
                          static_cast<int>(std::ceil(high.y() / pitch)) + 1};
    const World world = GenerateWorld(type, seed, nodes);
    const double cell = std::max(clearance_m, 1.0);
    const auto key = [cell](double x, double y) {
        return std::pair<std::int64_t, std::int64_t>(
            static_cast<std::int64_t>(std::floor(x / cell)),
            static_cast<std::int64_t>(std::floor(y / cell)));
    };
    std::map<std::pair<std::int64_t, std::int64_t>, std::vector<std::size_t>> grid;
    for (std::size_t i = 0; i < samples.size(); ++i)
        grid[key(samples[i].x(), samples[i].y())].push_back(i);
    std::vector<Shape> kept;
    for (const Shape& shape : world.objects()) {
        const Aabb box = Bounds(shape);
        const Eigen::Vector2d lo = box.min_m.head<2>().array() - clearance_m;
        const Eigen::Vector2d hi = box.max_m.head<2>().array() + clearance_m;
        bool near = false;
        const auto [x0, y0] = key(lo.x(), lo.y());
        const auto [x1, y1] = key(hi.x(), hi.y());
        for (std::int64_t x = x0; x <= x1 && !near; ++x) {
            for (std::int64_t y = y0; y <= y1 && !near; ++y) {
                const auto cell_samples = grid.find({x, y});
                if (cell_samples == grid.end()) continue;
                for (const std::size_t i : cell_samples->second) {
                    const Eigen::Vector2d& p = samples[i];
                    if ((p.array() >= lo.array()).all() && (p.array() <= hi.array()).all()) {
                        near = true;
                        break;
                    }
                }
            }
        }
        if (!near) kept.push_back(shape);
    }
    return World(world.ground(), world.ceiling_height_m(), std::move(kept), world.grid_cell_m());
}

void SimulationConfig::Validate() const {
    if (scans < 1 || scans > kMaxScans) {
        throw core::ConfigError("scans must be in [1, 1000000], got " + std::to_string(scans));
    }
    if (!trajectory.empty() && trajectory.size() != scans) {
        throw core::ConfigError("scans (" + std::to_string(scans) +
                                ") must equal the trajectory's poses (" +
                                std::to_string(trajectory.size()) + ")");
    }
    route.Validate();
    sensor.Validate();
    odometry.Validate();
    front_end.Validate();
}

Simulator::Simulator(const SimulationConfig& config)
    : config_(config),
      sensor_(ResolveFor(config, LayoutOf(config.scene))),
      layout_(LayoutOf(config.scene)),
      spacing_(config.route.spacing_min_m, config.route.spacing_max_m, config.seed),
      route_(RouteLegs(config.route.type, UturnBlocks(config, layout_)), layout_),
      world_(MakeWorld(config, layout_, route_,
                       config.trajectory.empty() ? std::vector<RoutePoint>{}
                                                 : PlanarTrajectory(config.trajectory))),
      directions_(BeamDirections(sensor_)) {
    if (!config.trajectory.empty()) trajectory_ = PlanarTrajectory(config.trajectory);
    if (config.route.type == RouteType::kUTurn) {
        config_.route.uturn_blocks = UturnBlocks(config, layout_);
    }
    config_.sensor.horizontal_steps = sensor_.horizontal_steps;
    config_.sensor.min_range_m = sensor_.min_range_m;
    config_.sensor.max_range_m = sensor_.max_range_m;
    config_.sensor.mount_height_m = sensor_.mount_height_m;
    config_.sensor.scan_period_s = sensor_.scan_period_s;
    core::Transform odometry = GroundTruthPose(0).T_world_sensor;
    core::Transform previous = odometry;
    odometry_checkpoints_.push_back(odometry);
    for (std::size_t i = 1; i < size(); ++i) {
        const core::Transform current = GroundTruthPose(i).T_world_sensor;
        odometry =
            odometry * MeasureStep(previous.inverse() * current, config_.odometry, config_.seed, i);
        if (i % kCheckpointStride == 0) odometry_checkpoints_.push_back(odometry);
        previous = current;
    }
}

void Simulator::CheckIndex(std::size_t index) const {
    if (index >= size()) {
        throw std::out_of_range("scan index " + std::to_string(index) + " is not below " +
                                std::to_string(size()));
    }
}

RoutePoint Simulator::PointAt(std::size_t index) const {
    if (!trajectory_.empty()) return trajectory_[index];
    return route_.At(spacing_.ArcLength(index));
}

core::StampedPose Simulator::GroundTruthPose(std::size_t index) const {
    CheckIndex(index);
    return {static_cast<double>(index) * sensor_.scan_period_s,
            VehiclePose(PointAt(index), world_.ground(), sensor_.mount_height_m), std::nullopt};
}

core::StampedPose Simulator::OdometryPose(std::size_t index) const {
    return OdometryPoses(index, 1).front();
}

std::vector<core::StampedPose> Simulator::OdometryPoses(std::size_t first,
                                                        std::size_t count) const {
    if (count == 0) return {};
    CheckIndex(first + count - 1);
    // Replay the measured steps from the checkpoint at or before `first`.
    const std::size_t start = first / kCheckpointStride * kCheckpointStride;
    core::Transform odometry = odometry_checkpoints_[first / kCheckpointStride];
    core::Transform previous = GroundTruthPose(start).T_world_sensor;
    std::vector<core::StampedPose> poses;
    poses.reserve(count);
    for (std::size_t i = start; i < first + count; ++i) {
        if (i > start) {
            const core::Transform current = GroundTruthPose(i).T_world_sensor;
            odometry = odometry *
                       MeasureStep(previous.inverse() * current, config_.odometry, config_.seed, i);
            previous = current;
        }
        if (i >= first)
            poses.push_back(
                {static_cast<double>(i) * sensor_.scan_period_s, odometry, std::nullopt});
    }
    return poses;
}

std::vector<Eigen::Vector3d> Simulator::ScanDirections(std::size_t index) const {
    CheckIndex(index);
    if (RepeatsEveryScan(sensor_.model)) return directions_;
    return BeamDirections(sensor_, index);
}

core::PointCloud Simulator::Scan(std::size_t index) const {
    const core::Transform T_world_sensor = GroundTruthPose(index).T_world_sensor;
    // The repeating sensors' rays are computed once; a non-repetitive one's for each scan.
    const bool repeats = RepeatsEveryScan(sensor_.model);
    std::vector<Eigen::Vector3d> own_directions;
    if (!repeats) own_directions = BeamDirections(sensor_, index);
    const std::vector<Eigen::Vector3d>& directions = repeats ? directions_ : own_directions;
    const Eigen::Matrix3d R = T_world_sensor.linear();
    detail::Random rng(detail::StreamSeed(config_.seed, detail::Stream::kScan,
                                          {static_cast<std::int64_t>(index)}));
    core::PointCloud cloud;
    cloud.reserve(directions_.size());
    Ray ray{T_world_sensor.translation(), Eigen::Vector3d::UnitX()};
    for (const Eigen::Vector3d& direction : directions) {
        ray.direction = R * direction;
        const double range = world_.CastRay(ray, sensor_.max_range_m);
        if (range == kNoHit || range < sensor_.min_range_m) continue;
        // Draws only for returns; the returns are the same for the same (config, index).
        if (rng.Uniform() < sensor_.dropout) continue;
        const double measured = range + sensor_.noise_m * rng.Normal();
        if (measured <= 0.0) continue;
        cloud.push_back((measured * direction).cast<float>());
    }
    if (config_.front_end.keep_every > 1) return KeepEvery(cloud, config_.front_end.keep_every);
    return cloud;
}

std::size_t CountRevisitedScans(const Simulator& simulator, std::size_t min_index_gap,
                                double max_distance_m) {
    const std::size_t n = simulator.size();
    std::vector<Eigen::Vector3d> positions(n);
    for (std::size_t i = 0; i < n; ++i) {
        positions[i] = simulator.GroundTruthPose(i).T_world_sensor.translation();
    }
    const auto key = [max_distance_m](const Eigen::Vector3d& p, int dx, int dy) {
        const auto cx = static_cast<std::int64_t>(std::floor(p.x() / max_distance_m)) + dx;
        const auto cy = static_cast<std::int64_t>(std::floor(p.y() / max_distance_m)) + dy;
        return static_cast<std::uint64_t>(cx) * 0x9e3779b97f4a7c15ULL ^
               static_cast<std::uint64_t>(cy);
    };
    std::unordered_map<std::uint64_t, std::vector<std::size_t>> grid;
    std::size_t revisited = 0;
    for (std::size_t i = min_index_gap; i < n; ++i) {
        grid[key(positions[i - min_index_gap], 0, 0)].push_back(i - min_index_gap);
        bool found = false;
        for (int dx = -1; dx <= 1 && !found; ++dx) {
            for (int dy = -1; dy <= 1 && !found; ++dy) {
                const auto cell = grid.find(key(positions[i], dx, dy));
                if (cell == grid.end()) continue;
                for (const std::size_t j : cell->second) {
                    if ((positions[j] - positions[i]).norm() <= max_distance_m) {
                        found = true;
                        break;
                    }
                }
            }
        }
        if (found) ++revisited;
    }
    return revisited;
}

SimulationConfig DemoConfig() {
    SimulationConfig config;
    config.scene = SceneType::kUrban;
    config.route.type = RouteType::kGrid;
    config.route.spacing_min_m = 2.5;
    config.route.spacing_max_m = 3.5;
    config.sensor.model = SensorModel::kVlp16;
    // 16 x 1024 rays (~14k points): enough for NDT cells of q = 0.5 m to see shapes, and the
    // whole sequence is generated in about a second (70 MB, not bundled).
    config.sensor.horizontal_steps = 1024;
    config.sensor.scan_period_s = 0.25;
    config.scans = 320;
    config.seed = 1;
    return config;
}

}  // namespace lidarloop::sim

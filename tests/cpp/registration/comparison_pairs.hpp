#pragma once

// Scan pairs with a known relative pose, shared by the test that judges lidarloop's verification
// by the Open3D oracle and by the tool that times both (tests/tools/verify_vs_open3d.cpp): the
// real KITTI samples (read from outside the repository) and simulated pairs with exact ground
// truth.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/io/kitti_bin.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/sim/simulator.hpp"

namespace lidarloop::test {

/// What a pair of scans is.
enum class PairKind {
    kLoop,            ///< the same place revisited (another direction or lane)
    kConsecutive,     ///< consecutive scans of a drive
    kDifferentPlace,  ///< scans of places far apart: must be rejected
};

inline const char* ToString(PairKind kind) {
    switch (kind) {
        case PairKind::kLoop:
            return "loop";
        case PairKind::kConsecutive:
            return "consecutive";
        case PairKind::kDifferentPlace:
            return "other place";
    }
    return "?";
}

/// Two scans (sensor frames, metres) and the ground truth T_match_query.
struct ScanPair {
    std::string name;  ///< e.g. "kitti 08 1684->209", "urban hdl64 opposite 182->31"
    PairKind kind = PairKind::kLoop;
    core::PointCloud query;
    core::PointCloud match;
    core::Transform T_match_query_truth = core::Transform::Identity();
    /// True for simulated pairs and KITTI's consecutive scans; KITTI's poses drift between the
    /// visits of a loop (by 0.4-1.2 m planar, 1-2.6 m vertical: the samples' README.md).
    bool exact_truth = true;
};

/// How far apart two relative poses are.
struct PoseDifference {
    double translation_m = 0.0;  ///< |t_a - t_b|
    double planar_m = 0.0;       ///< |t_a - t_b| in x, y
    double vertical_m = 0.0;     ///< z_a - z_b
    double rotation_deg = 0.0;   ///< angle of R_a^T R_b
    double yaw_deg = 0.0;        ///< yaw_a - yaw_b wrapped to [-180, 180)
};

inline double YawDeg(const core::Transform& T) {
    return std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * 180.0 / std::numbers::pi;
}

inline PoseDifference Difference(const core::Transform& a, const core::Transform& b) {
    PoseDifference d;
    const Eigen::Vector3d dt = a.translation() - b.translation();
    d.translation_m = dt.norm();
    d.planar_m = dt.head<2>().norm();
    d.vertical_m = dt.z();
    d.rotation_deg =
        Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / std::numbers::pi;
    d.yaw_deg = std::remainder(YawDeg(a) - YawDeg(b), 360.0);
    return d;
}

/// The real KITTI pairs of the samples' README.md (`dir`: ../shared/data/kitti-samples): both
/// loops of 08 (revisited in the opposite direction), the consecutive pairs of 00 and, when
/// `with_other_places`, two pairs of different places (00 198->94, 58 m apart; 08 720->209, 93 m).
/// Empty when `dir` has no README.md (the samples are not in the repository).
inline std::vector<ScanPair> KittiPairs(const std::filesystem::path& dir,
                                        bool with_other_places = true) {
    std::vector<ScanPair> pairs;
    if (!std::filesystem::exists(dir / "README.md")) return pairs;
    const auto scan = [&](const std::string& sequence, int frame) {
        char name[16];
        std::snprintf(name, sizeof name, "%06d.bin", frame);
        return io::ReadKittiBin(dir / sequence / "velodyne" / name);
    };
    const auto add = [&](const std::string& sequence, int query, int match, PairKind kind) {
        const core::Transform T_cam0_velo =
            io::ReadKittiCalibTr(dir / ("calib_" + sequence + ".txt"));
        const auto poses = io::ReadKittiPoses(dir / "poses" / (sequence + ".txt"), T_cam0_velo);
        ScanPair pair;
        pair.name =
            "kitti " + sequence + " " + std::to_string(query) + "->" + std::to_string(match);
        pair.kind = kind;
        pair.query = scan(sequence, query);
        pair.match = scan(sequence, match);
        pair.T_match_query_truth =
            poses.at(static_cast<std::size_t>(match)).T_world_sensor.inverse() *
            poses.at(static_cast<std::size_t>(query)).T_world_sensor;
        pair.exact_truth = kind != PairKind::kLoop;
        pairs.push_back(std::move(pair));
    };
    add("08", 1684, 209, PairKind::kLoop);
    add("08", 1500, 720, PairKind::kLoop);
    add("00", 95, 94, PairKind::kConsecutive);
    add("00", 199, 198, PairKind::kConsecutive);
    if (with_other_places) {
        add("00", 198, 94, PairKind::kDifferentPlace);
        add("08", 720, 209, PairKind::kDifferentPlace);
    }
    return pairs;
}

/// A simulated U-turn drive (seed 1) through `scene` with `sensor`: out along a street in the
/// inner lane, back in the opposite direction one lane to the side, then the same in the outer
/// lanes. `horizontal_steps` thins the scans (0: the sensor's own, 1875 or 1800).
inline sim::SimulationConfig UTurnDrive(sim::SceneType scene, sim::SensorModel sensor,
                                        int horizontal_steps = 0) {
    sim::SimulationConfig config;
    config.scene = scene;
    config.route.type = sim::RouteType::kUTurn;
    // One block of the rural scene is 160 m; the others' street of 2-4 blocks is 40-140 m.
    config.route.uturn_blocks = scene == sim::SceneType::kRural ? 1 : 2;
    config.sensor.model = sensor;
    if (horizontal_steps > 0) config.sensor.horizontal_steps = horizontal_steps;
    config.scans = 1200;  // more than a lap; only the scans of the pairs are ray cast
    config.seed = 1;
    return config;
}

/// Three pairs of a simulated drive, found from the ground truth: the first scan that revisits
/// a place in the opposite direction (the nearest earlier scan within 5 m, heading reversed; a
/// lane to the side), the first that revisits one in the same direction a lane to the side
/// (within 5 m, more than 2 m apart, at least 30 scans later), and the opposite-direction query
/// with the scan of the drive farthest from it.
inline std::vector<ScanPair> SimulatedPairs(const sim::Simulator& simulator,
                                            const std::string& label) {
    std::vector<core::Transform> poses(simulator.size());
    for (std::size_t i = 0; i < poses.size(); ++i)
        poses[i] = simulator.GroundTruthPose(i).T_world_sensor;
    const auto pose = [&](std::size_t i) -> const core::Transform& { return poses[i]; };
    // The earliest (query, match) with match + 30 < query whose headings and distance pass.
    const auto find = [&](auto accept) -> std::optional<std::pair<std::size_t, std::size_t>> {
        for (std::size_t i = 31; i < simulator.size(); ++i) {
            std::optional<std::size_t> best;
            double best_m = INFINITY;
            for (std::size_t j = 0; j + 30 < i; ++j) {
                const double heading = pose(i).linear().col(0).dot(pose(j).linear().col(0));
                const double d = (pose(i).translation() - pose(j).translation()).norm();
                if (accept(heading, d) && d < best_m) {
                    best = j;
                    best_m = d;
                }
            }
            if (best) return std::pair{i, *best};
        }
        return std::nullopt;
    };
    std::vector<ScanPair> pairs;
    const auto add = [&](std::size_t query, std::size_t match, PairKind kind, const char* what) {
        ScanPair pair;
        pair.name = label + " " + what + " " + std::to_string(query) + "->" + std::to_string(match);
        pair.kind = kind;
        pair.query = simulator.Scan(query);
        pair.match = simulator.Scan(match);
        pair.T_match_query_truth = pose(match).inverse() * pose(query);
        pairs.push_back(std::move(pair));
    };
    const auto opposite = find([](double heading, double d) { return heading < -0.9 && d < 5.0; });
    const auto same =
        find([](double heading, double d) { return heading > 0.9 && d > 2.0 && d < 5.0; });
    if (opposite) add(opposite->first, opposite->second, PairKind::kLoop, "opposite");
    if (same) add(same->first, same->second, PairKind::kLoop, "same-dir");
    if (opposite) {
        // The scan farthest from the opposite-direction query: another place in every scene,
        // though in the mine and indoor scenes one built like it (pillars, rooms every 10-20 m).
        const std::size_t query = opposite->first;
        std::size_t farthest = 0;
        for (std::size_t j = 0; j < poses.size(); ++j) {
            const auto distance = [&](std::size_t k) {
                return (pose(query).translation() - pose(k).translation()).norm();
            };
            if (distance(j) > distance(farthest)) farthest = j;
        }
        add(query, farthest, PairKind::kDifferentPlace, "other");
    }
    return pairs;
}

}  // namespace lidarloop::test

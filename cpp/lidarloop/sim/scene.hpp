#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "lidarloop/sim/terrain.hpp"
#include "lidarloop/sim/world.hpp"

namespace lidarloop::sim {

/// Kinds of generated environments. All are laid out on a square grid of streets (corridors,
/// drifts) whose centre lines are `block_pitch_m` apart; the blocks between them are filled with
/// the scene's content, and the streets are kept free where the vehicle drives.
enum class SceneType {
    kUrban,   ///< 70 m blocks of box and L-shaped buildings, walls, street lights, trees,
              ///< parked cars; four-lane streets; gently rolling ground
    kRural,   ///< 160 m blocks of fields, farms, silos, forest patches and orchards along an
              ///< open road with utility poles, tree rows and delineator posts; rolling hills
    kMine,    ///< room-and-pillar mine like Kvarntorp: 10 m drifts between irregular 10 m
              ///< rock pillars under a 4.5 m roof; very self-similar
    kIndoor,  ///< office floor: 3 m corridors between rooms with doors (some open at an angle),
              ///< desks, cabinets, chairs, plants; 2.7 m ceiling; flat floor
};

std::string ToString(SceneType type);
/// Parses "urban" / "rural" / "mine" / "indoor"; throws core::ConfigError listing the names.
SceneType ParseSceneType(std::string_view name);

/// The street grid geometry of a scene type (metres).
struct SceneLayout {
    double block_pitch_m = 70.0;          ///< distance between parallel street centre lines
    double corridor_half_width_m = 12.0;  ///< street half width kept free of block content
    double road_half_width_m = 7.2;       ///< half width kept free of every object
    double lane_width_m = 3.5;      ///< lane k is centred (k + 0.5) lane widths right of the centre
    double vehicle_radius_m = 1.0;  ///< horizontal clearance of the vehicle
    double ceiling_height_m = 0.0;  ///< ceiling above the ground; 0: open sky
    double grid_cell_m = 4.0;       ///< cell of the world's ray casting grid
    double path_smoothing_m = 3.0;  ///< sigma of the Gaussian that rounds route corners
    double terrain_amplitude_m = 2.5;  ///< bound of the ground's height variation
    double terrain_max_slope = 0.04;   ///< bound of the ground's gradient (rise over run)
    double terrain_min_wavelength_m = 250.0;
    double terrain_max_wavelength_m = 600.0;
};

/// The layout of each scene type (the numbers in the SceneType comments).
SceneLayout LayoutOf(SceneType type);

/// A rectangle of street nodes: node (i, j), i in [i_min, i_max], j in [j_min, j_max], lies at
/// (i, j) * block_pitch_m in the world frame; the blocks are the squares between them.
struct NodeRange {
    int i_min = 0;
    int i_max = 1;
    int j_min = 0;
    int j_max = 1;
};

/// The ground of a scene: three seeded sinusoids within the layout's amplitude and slope bounds
/// (flat for kIndoor).
Terrain GenerateTerrain(SceneType type, std::uint64_t seed);

/// Generates the world of a scene over the blocks and streets of `nodes`. Every block and street
/// segment draws its content from its own seeded stream (seed, scene, block index), so the same
/// seed gives the same world, and a larger node range the same content where the ranges
/// overlap. Enclosed scenes (mine, indoor) get solid walls around the outermost streets. Objects
/// are placed only inside blocks and on the street sides beyond road_half_width_m, never in the
/// driven part of a street or in an intersection. Throws core::ConfigError for an empty range
/// or one of more than 1e6 blocks.
World GenerateWorld(SceneType type, std::uint64_t seed, const NodeRange& nodes);

}  // namespace lidarloop::sim

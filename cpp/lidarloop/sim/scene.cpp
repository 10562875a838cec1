#include "lidarloop/sim/scene.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/sim/detail/random.hpp"
#include "lidarloop/sim/detail/scene_builder.hpp"

namespace lidarloop::sim {
namespace {

using detail::Random;
using detail::Rect;
using detail::SceneBuilder;
using detail::StreetFrame;

constexpr double kEnclosureThickness_m = 3.0;
constexpr double kMaxBlocks = 1e6;

void FillBlock(SceneType type, const Rect& block, Random& rng, SceneBuilder& builder) {
    switch (type) {
        case SceneType::kUrban:
            return detail::FillUrbanBlock(block, rng, builder);
        case SceneType::kRural:
            return detail::FillRuralBlock(block, rng, builder);
        case SceneType::kMine:
            return detail::FillMineBlock(block, rng, builder);
        case SceneType::kIndoor:
            return detail::FillIndoorBlock(block, rng, builder);
    }
}

void FillStreet(SceneType type, const StreetFrame& street, Random& rng, SceneBuilder& builder) {
    switch (type) {
        case SceneType::kUrban:
            return detail::FillUrbanStreet(street, rng, builder);
        case SceneType::kRural:
            return detail::FillRuralStreet(street, rng, builder);
        case SceneType::kMine:
            return detail::FillMineStreet(street, rng, builder);
        case SceneType::kIndoor:
            return detail::FillIndoorStreet(street, rng, builder);
    }
}

// Solid walls just outside the outermost streets, so that tunnels and floors are closed.
void AddEnclosure(const NodeRange& nodes, const SceneLayout& layout, SceneBuilder& builder) {
    const double p = layout.block_pitch_m;
    const double outer = layout.corridor_half_width_m + 0.5 * kEnclosureThickness_m;
    const double x0 = nodes.i_min * p - outer;
    const double x1 = nodes.i_max * p + outer;
    const double y0 = nodes.j_min * p - outer;
    const double y1 = nodes.j_max * p + outer;
    const double t = kEnclosureThickness_m;
    builder.SolidWall({x0 - 0.5 * t, y0}, {x1 + 0.5 * t, y0}, t);
    builder.SolidWall({x0 - 0.5 * t, y1}, {x1 + 0.5 * t, y1}, t);
    builder.SolidWall({x0, y0}, {x0, y1}, t);
    builder.SolidWall({x1, y0}, {x1, y1}, t);
}

void AddStreets(SceneType type, std::uint64_t seed, const NodeRange& nodes,
                const SceneLayout& layout, SceneBuilder& builder) {
    const double p = layout.block_pitch_m;
    const double hw = layout.corridor_half_width_m;
    const auto type_index = static_cast<std::int64_t>(type);
    for (int axis = 0; axis < 2; ++axis) {
        const Eigen::Vector2d direction =
            axis == 0 ? Eigen::Vector2d::UnitX() : Eigen::Vector2d::UnitY();
        const int i_end = axis == 0 ? nodes.i_max - 1 : nodes.i_max;
        const int j_end = axis == 0 ? nodes.j_max : nodes.j_max - 1;
        for (int j = nodes.j_min; j <= j_end; ++j) {
            for (int i = nodes.i_min; i <= i_end; ++i) {
                const Eigen::Vector2d node(i * p, j * p);
                const StreetFrame street{node + hw * direction, direction, p - 2.0 * hw};
                Random rng(
                    detail::StreamSeed(seed, detail::Stream::kStreet, {type_index, axis, i, j}));
                FillStreet(type, street, rng, builder);
            }
        }
    }
}

constexpr auto kSceneTypeNames = std::to_array<core::EnumName<SceneType>>({
    {SceneType::kUrban, "urban"},
    {SceneType::kRural, "rural"},
    {SceneType::kMine, "mine"},
    {SceneType::kIndoor, "indoor"},
});
static_assert(core::IsOneToOne(kSceneTypeNames));

}  // namespace

std::string ToString(SceneType type) { return std::string(core::NameOf(kSceneTypeNames, type)); }

SceneType ParseSceneType(std::string_view name) {
    return core::ParseEnum(kSceneTypeNames, name, "scene");
}

SceneLayout LayoutOf(SceneType type) {
    switch (type) {
        case SceneType::kUrban:
            return {};
        case SceneType::kRural:
            return {.block_pitch_m = 160.0,
                    .corridor_half_width_m = 14.0,
                    .road_half_width_m = 7.5,
                    .grid_cell_m = 6.0,
                    .terrain_amplitude_m = 6.0,
                    .terrain_max_slope = 0.06,
                    .terrain_min_wavelength_m = 400.0,
                    .terrain_max_wavelength_m = 900.0};
        case SceneType::kMine:
            return {.block_pitch_m = 20.0,
                    .corridor_half_width_m = 5.0,
                    .road_half_width_m = 4.0,
                    .lane_width_m = 2.0,
                    .vehicle_radius_m = 0.6,
                    .ceiling_height_m = 4.5,
                    .grid_cell_m = 2.0,
                    .path_smoothing_m = 1.5,
                    .terrain_amplitude_m = 0.8,
                    .terrain_max_slope = 0.03,
                    .terrain_min_wavelength_m = 60.0,
                    .terrain_max_wavelength_m = 150.0};
        case SceneType::kIndoor:
            return {.block_pitch_m = 10.0,
                    .corridor_half_width_m = 1.5,
                    .road_half_width_m = 1.35,
                    .lane_width_m = 0.6,
                    .vehicle_radius_m = 0.35,
                    .ceiling_height_m = 2.7,
                    .grid_cell_m = 1.0,
                    .path_smoothing_m = 0.4,
                    .terrain_amplitude_m = 0.0,
                    .terrain_max_slope = 0.0};
    }
    return {};
}

Terrain GenerateTerrain(SceneType type, std::uint64_t seed) {
    const SceneLayout layout = LayoutOf(type);
    if (layout.terrain_amplitude_m <= 0.0 || layout.terrain_max_slope <= 0.0) return Terrain();
    Random rng(detail::StreamSeed(seed, detail::Stream::kTerrain, {static_cast<int>(type)}));
    std::vector<TerrainWave> waves(3);
    double weight_sum = 0.0;
    double slope_sum = 0.0;
    for (auto& wave : waves) {
        const double wavelength =
            rng.Uniform(layout.terrain_min_wavelength_m, layout.terrain_max_wavelength_m);
        const double direction = rng.Uniform(0.0, 2.0 * std::numbers::pi);
        const double k = 2.0 * std::numbers::pi / wavelength;
        wave.wavenumber_rad_per_m = {k * std::cos(direction), k * std::sin(direction)};
        wave.phase_rad = rng.Uniform(0.0, 2.0 * std::numbers::pi);
        wave.amplitude_m = rng.Uniform(0.3, 1.0);  // a weight, scaled below
        weight_sum += wave.amplitude_m;
        slope_sum += wave.amplitude_m * k;
    }
    const double scale =
        std::min(layout.terrain_amplitude_m / weight_sum, layout.terrain_max_slope / slope_sum);
    for (auto& wave : waves) wave.amplitude_m *= scale;
    return Terrain(std::move(waves));
}

World GenerateWorld(SceneType type, std::uint64_t seed, const NodeRange& nodes) {
    const double blocks = (static_cast<double>(nodes.i_max) - nodes.i_min) *
                          (static_cast<double>(nodes.j_max) - nodes.j_min);
    if (nodes.i_max <= nodes.i_min || nodes.j_max <= nodes.j_min || blocks > kMaxBlocks) {
        throw core::ConfigError("scene node range must span 1 to 1e6 blocks, got i in [" +
                                std::to_string(nodes.i_min) + ", " + std::to_string(nodes.i_max) +
                                "], j in [" + std::to_string(nodes.j_min) + ", " +
                                std::to_string(nodes.j_max) + "]");
    }
    const SceneLayout layout = LayoutOf(type);
    const Terrain terrain = GenerateTerrain(type, seed);
    std::vector<Shape> objects;
    SceneBuilder builder(terrain, layout, objects);
    const double p = layout.block_pitch_m;
    const double hw = layout.corridor_half_width_m;
    for (int j = nodes.j_min; j < nodes.j_max; ++j) {
        for (int i = nodes.i_min; i < nodes.i_max; ++i) {
            const Rect block{i * p + hw, j * p + hw, (i + 1) * p - hw, (j + 1) * p - hw};
            Random rng(detail::StreamSeed(seed, detail::Stream::kBlock,
                                          {static_cast<std::int64_t>(type), i, j}));
            FillBlock(type, block, rng, builder);
        }
    }
    AddStreets(type, seed, nodes, layout, builder);
    if (layout.ceiling_height_m > 0.0) AddEnclosure(nodes, layout, builder);
    return World(terrain, layout.ceiling_height_m, std::move(objects), layout.grid_cell_m);
}

}  // namespace lidarloop::sim

#pragma once

#include <cstdint>

#include "lidarloop/sim/simulator.hpp"

namespace lidarloop::test {

/// Sparse keyframes as a LIO front end keeps them: `lidarloop simulate --scene SCENE --route uturn
/// --seed SEED --sensor SENSOR --keep-every N --scans 300 --spacing-min-m 1 --spacing-max-m 2`.
inline sim::SimulationConfig SparseUTurnKeyframes(
    sim::SceneType scene, std::int64_t keep_every,
    sim::SensorModel sensor = sim::SensorModel::kHdl32, std::uint64_t seed = 3) {
    sim::SimulationConfig config;
    config.scene = scene;
    config.route.type = sim::RouteType::kUTurn;
    config.route.spacing_min_m = 1.0;
    config.route.spacing_max_m = 2.0;
    config.sensor.model = sensor;
    config.front_end.keep_every = keep_every;
    config.scans = 300;
    config.seed = seed;
    return config;
}

}  // namespace lidarloop::test

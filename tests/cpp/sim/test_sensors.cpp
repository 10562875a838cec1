// The sparse and narrow sensors of issue 24 (hdl32, ouster64-wide, livox-avia) against their
// specifications, and a front end's thinning (front_end.keep_every).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/sim/simulator.hpp"
#include "sim/sim_test_utils.hpp"
#include "test_utils.hpp"

namespace lidarloop::sim {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

double ElevationDeg(const Eigen::Vector3d& d) { return std::asin(d.z() / d.norm()) * kRadToDeg; }
double AzimuthDeg(const Eigen::Vector3d& d) { return std::atan2(d.y(), d.x()) * kRadToDeg; }

// The distinct elevations of a scan's rays, rounded to 1e-6 degrees.
std::set<long long> DistinctElevations(const std::vector<Eigen::Vector3d>& directions) {
    std::set<long long> elevations;
    for (const auto& d : directions) elevations.insert(std::llround(ElevationDeg(d) * 1e6));
    return elevations;
}

// The fraction of `probes` with a ray of `directions` within `tolerance_deg` (brute force).
double FractionSampledAgain(const std::vector<Eigen::Vector3d>& probes,
                            const std::vector<Eigen::Vector3d>& directions, double tolerance_deg) {
    const double min_cos = std::cos(tolerance_deg / kRadToDeg);
    std::size_t again = 0;
    for (const auto& probe : probes) {
        const bool found = std::any_of(directions.begin(), directions.end(),
                                       [&](const auto& d) { return probe.dot(d) >= min_cos; });
        if (found) ++again;
    }
    return static_cast<double>(again) / static_cast<double>(probes.size());
}

std::vector<Eigen::Vector3d> EveryNth(const std::vector<Eigen::Vector3d>& directions,
                                      std::size_t n) {
    std::vector<Eigen::Vector3d> kept;
    for (std::size_t i = 0; i < directions.size(); i += n) kept.push_back(directions[i]);
    return kept;
}

// The 0.2 x 0.2 degree cells of azimuth and elevation that hold a ray.
std::set<std::pair<int, int>> CellsHit(const std::vector<Eigen::Vector3d>& directions) {
    std::set<std::pair<int, int>> cells;
    for (const auto& d : directions) {
        cells.insert({static_cast<int>(std::floor(AzimuthDeg(d) * 5.0)),
                      static_cast<int>(std::floor(ElevationDeg(d) * 5.0))});
    }
    return cells;
}

TEST(Sensors, NamesOfAllModelsRoundTrip) {
    for (const SensorModel model :
         {SensorModel::kHdl64, SensorModel::kVlp16, SensorModel::kTilt180, SensorModel::kHdl32,
          SensorModel::kOuster64Wide, SensorModel::kLivoxAvia}) {
        EXPECT_EQ(ParseSensorModel(ToString(model)), model);
    }
    EXPECT_EQ(ToString(SensorModel::kHdl32), "hdl32");
    EXPECT_EQ(ToString(SensorModel::kOuster64Wide), "ouster64-wide");
    EXPECT_EQ(ToString(SensorModel::kLivoxAvia), "livox-avia");
}

// HDL-32E data sheet: 32 lasers, +10.67 to -30.67 degrees (~1.33 apart), 360 degrees,
// ~695k points/s at 10 Hz, 100 m.
TEST(Sensors, Hdl32HasThirtyTwoBeamsFromMinus30p67ToPlus10p67) {
    const auto elevations = BeamElevationsDeg(SensorModel::kHdl32);
    ASSERT_EQ(elevations.size(), 32u);
    std::vector<double> sorted = elevations;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_NEAR(sorted.front(), -30.67, 1e-9);
    EXPECT_NEAR(sorted.back(), 10.67, 1e-9);
    for (std::size_t i = 1; i < sorted.size(); ++i) {
        EXPECT_NEAR(sorted[i] - sorted[i - 1], 41.34 / 31.0, 1e-9) << i;
    }
    // Interleaved firing: the lower and the upper half alternate.
    EXPECT_NEAR(elevations[0], -30.67, 1e-9);
    EXPECT_NEAR(elevations[1], -9.33, 0.01);
    EXPECT_NEAR(elevations[2], -29.33, 0.01);
    const SensorSpec spec = SpecOf(SensorModel::kHdl32);
    EXPECT_EQ(spec.beams, 32);
    EXPECT_EQ(spec.max_range_m, 100.0);
    const auto directions = BeamDirections(spec);
    EXPECT_EQ(directions.size(), 32u * 2170u);  // 69440 rays: ~70k points per revolution
    const auto distinct = DistinctElevations(directions);
    EXPECT_EQ(distinct.size(), 32u);
    EXPECT_GE(*distinct.begin(), std::llround(-30.67 * 1e6));
    EXPECT_LE(*distinct.rbegin(), std::llround(10.67 * 1e6));
    double min_x = 1.0;
    for (const auto& d : directions) min_x = std::min(min_x, d.x() / d.norm());
    EXPECT_LT(min_x, -0.8);  // 360 degrees: it looks backwards too
}

TEST(Sensors, Ouster64WideSpansNinetyDegreesUniformly) {
    const auto elevations = BeamElevationsDeg(SensorModel::kOuster64Wide);
    ASSERT_EQ(elevations.size(), 64u);
    EXPECT_NEAR(elevations.front(), 45.0, 1e-9);
    EXPECT_NEAR(elevations.back(), -45.0, 1e-9);
    for (std::size_t i = 1; i < elevations.size(); ++i) {
        EXPECT_NEAR(elevations[i - 1] - elevations[i], 90.0 / 63.0, 1e-9) << i;
    }
    const SensorSpec spec = SpecOf(SensorModel::kOuster64Wide);
    const auto directions = BeamDirections(spec);
    EXPECT_EQ(directions.size(), 64u * 1024u);
    EXPECT_EQ(DistinctElevations(directions).size(), 64u);
    SensorConfig fine;
    fine.model = SensorModel::kOuster64Wide;
    fine.horizontal_steps = 2048;
    EXPECT_EQ(BeamDirections(Resolve(fine)).size(), 64u * 2048u);
}

// Livox Avia data sheet: non-repetitive scanning over 70.4 x 77.2 degrees, forward only;
// 240k points/s, i.e. 24000 per 0.1 s scan.
TEST(Sensors, LivoxAviaStaysInsideItsFieldAndFillsIt) {
    const SensorSpec spec = SpecOf(SensorModel::kLivoxAvia);
    EXPECT_TRUE(BeamElevationsDeg(SensorModel::kLivoxAvia).empty());
    for (const std::size_t scan : {0u, 1u, 7u, 123456u}) {
        const auto directions = BeamDirections(spec, scan);
        ASSERT_EQ(directions.size(), 24000u);
        double max_azimuth = 0.0;
        double max_elevation = 0.0;
        for (const auto& d : directions) {
            ASSERT_NEAR(d.norm(), 1.0, 1e-12);
            ASSERT_GT(d.x(), 0.0);
            ASSERT_LE(std::abs(AzimuthDeg(d)), 35.2 + 1e-9);
            ASSERT_LE(std::abs(ElevationDeg(d)), 38.6 + 1e-9);
            max_azimuth = std::max(max_azimuth, std::abs(AzimuthDeg(d)));
            max_elevation = std::max(max_elevation, std::abs(ElevationDeg(d)));
        }
        // The rosette reaches the edges of the field.
        EXPECT_GT(max_azimuth, 34.0) << scan;
        EXPECT_GT(max_elevation, 37.5) << scan;
    }
    // The whole field is sampled in one scan: every 5 x 5 degree cell inside the ellipse.
    std::set<std::pair<int, int>> coarse;
    for (const auto& d : BeamDirections(spec, 3)) {
        coarse.insert({static_cast<int>(std::floor(AzimuthDeg(d) / 5.0)),
                       static_cast<int>(std::floor(ElevationDeg(d) / 5.0))});
    }
    for (int a = -6; a < 6; ++a) {
        for (int e = -6; e < 6; ++e) {
            const double az = (a + 0.5) * 5.0, el = (e + 0.5) * 5.0;
            if (std::hypot(az / 30.0, el / 33.0) > 1.0) continue;  // well inside the field
            EXPECT_TRUE(coarse.count({a, e})) << az << " " << el;
        }
    }
}

TEST(Sensors, LivoxAviaSamplesNewDirectionsInEveryScan) {
    const SensorSpec spec = SpecOf(SensorModel::kLivoxAvia);
    const auto scan0 = BeamDirections(spec, 0);
    const auto scan1 = BeamDirections(spec, 1);
    // Deterministic per scan, different from scan to scan.
    EXPECT_EQ(BeamDirections(spec, 1), scan1);
    EXPECT_LT(FractionSampledAgain(EveryNth(scan1, 24), scan0, 0.01), 0.02);
    EXPECT_GT(FractionSampledAgain(EveryNth(scan1, 24), scan1, 0.01), 0.99);  // the probe works
    // Non-repetitive: integrating scans covers ever more of the field.
    std::vector<Eigen::Vector3d> integrated;
    std::vector<double> cells;  // cells hit by the scans so far
    for (std::size_t scan = 0; scan < 5; ++scan) {
        const auto directions = BeamDirections(spec, scan);
        integrated.insert(integrated.end(), directions.begin(), directions.end());
        cells.push_back(static_cast<double>(CellsHit(integrated).size()));
    }
    // Measured: 20k cells of 0.2 degrees after one scan, 39k after two, 72k after five (of
    // about 107k in the field); a repeating pattern would stay at 20k.
    EXPECT_GT(cells[1], cells[0] * 1.5);
    EXPECT_GT(cells[4], cells[0] * 3.0);
    // The repetitive sensors sample the same directions in every scan.
    for (const SensorModel model : {SensorModel::kHdl32, SensorModel::kOuster64Wide}) {
        EXPECT_TRUE(RepeatsEveryScan(model));
        EXPECT_EQ(BeamDirections(SpecOf(model), 0), BeamDirections(SpecOf(model), 1));
    }
    EXPECT_FALSE(RepeatsEveryScan(SensorModel::kLivoxAvia));
}

SimulationConfig IndoorConfig(SensorModel model) {
    SimulationConfig config;
    config.scene = SceneType::kIndoor;
    config.route.type = RouteType::kGrid;
    config.route.spacing_min_m = 0.4;
    config.route.spacing_max_m = 0.8;
    config.sensor.model = model;
    config.sensor.dropout = 0.0;
    config.sensor.noise_m = 0.0;
    config.scans = 8;
    config.seed = 5;
    return config;
}

// In a closed room every ray returns: the point count is the data sheet's rays per scan.
TEST(Sensors, PointsPerScanInAClosedSceneAreTheRaysOfTheDataSheet) {
    const std::vector<std::pair<SensorModel, std::size_t>> rays = {
        {SensorModel::kHdl32, 69440u},
        {SensorModel::kOuster64Wide, 65536u},
        {SensorModel::kLivoxAvia, 24000u}};
    for (const auto& [model, count] : rays) {
        const Simulator simulator(IndoorConfig(model));
        EXPECT_EQ(simulator.Scan(3).size(), count) << ToString(model);
    }
}

// Every simulated point lies along a ray of its own scan, inside the Avia's field; a
// consecutive scan of the same place samples other directions.
TEST(Sensors, LivoxAviaScansFollowTheirOwnScansRays) {
    const Simulator simulator(IndoorConfig(SensorModel::kLivoxAvia));
    const core::PointCloud cloud = simulator.Scan(4);
    std::vector<Eigen::Vector3d> point_directions;
    for (const auto& p : cloud) {
        const Eigen::Vector3d d = p.cast<double>().normalized();
        ASSERT_GT(d.x(), 0.0);
        ASSERT_LE(std::abs(AzimuthDeg(d)), 35.2 + 1e-4);
        ASSERT_LE(std::abs(ElevationDeg(d)), 38.6 + 1e-4);
        point_directions.push_back(d);
    }
    const auto rays = simulator.ScanDirections(4);
    ASSERT_EQ(rays.size(), point_directions.size());  // no dropout, a closed room
    for (std::size_t i = 0; i < rays.size(); i += 97) {
        ASSERT_GT(rays[i].dot(point_directions[i]), std::cos(1e-5)) << i;
    }
    const auto probes = EveryNth(point_directions, 24);
    EXPECT_GT(FractionSampledAgain(probes, simulator.ScanDirections(4), 0.01), 0.99);
    EXPECT_LT(FractionSampledAgain(probes, simulator.ScanDirections(3), 0.01), 0.02);
}

// A front end's thinning keeps exactly points 0, N, 2N, ... of the full scan, dropouts and noise
// unchanged, for every sensor.
TEST(FrontEnd, KeepEveryNthPointKeepsExactlyThoseOfTheFullScan) {
    for (const SensorModel model : {SensorModel::kHdl32, SensorModel::kLivoxAvia}) {
        SimulationConfig config;
        config.route.type = RouteType::kGrid;
        config.sensor.model = model;
        config.sensor.horizontal_steps = 500;
        config.scans = 6;
        const Simulator full(config);
        for (const std::int64_t n : {2, 3, 10}) {
            config.front_end.keep_every = n;
            const Simulator thinned(config);
            EXPECT_EQ(thinned.config().front_end.keep_every, n);
            const core::PointCloud all = full.Scan(5);
            const core::PointCloud kept = thinned.Scan(5);
            const std::size_t step = static_cast<std::size_t>(n);
            ASSERT_EQ(kept.size(), (all.size() + step - 1) / step) << ToString(model) << " " << n;
            core::PointCloud expected;
            for (std::size_t i = 0; i < all.size(); i += step) expected.push_back(all[i]);
            EXPECT_TRUE(SameBytes(kept, expected)) << ToString(model) << " " << n;
        }
    }
    EXPECT_TRUE(SameBytes(KeepEvery(test::RandomCloud(10, 1), 1), test::RandomCloud(10, 1)));
    EXPECT_EQ(KeepEvery(test::RandomCloud(10, 1), 4).size(), 3u);
    EXPECT_THROW(KeepEvery(test::RandomCloud(10, 1), 0), core::ConfigError);
}

TEST(FrontEnd, AbsurdThinningIsRejected) {
    for (const std::int64_t n :
         {std::int64_t{0}, std::int64_t{-3}, std::int64_t{1001}, std::int64_t{1} << 40}) {
        SimulationConfig config;
        config.front_end.keep_every = n;
        EXPECT_TRUE(
            test::Contains(test::ConfigErrorOf([&] { config.Validate(); }),
                           "front_end.keep_every must be in [1, 1000], got " + std::to_string(n)));
        EXPECT_THROW(Simulator{config}, core::ConfigError);
    }
    SimulationConfig config;
    config.front_end.keep_every = 1000;
    EXPECT_NO_THROW(config.Validate());
    EXPECT_EQ(SimulationConfig{}.front_end.keep_every, 1);  // the default keeps every point
}

}  // namespace
}  // namespace lidarloop::sim

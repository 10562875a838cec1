#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace lidarloop::sim {

/// Simulated scanners. Directions are in the sensor frame: x forward, y left, z up.
enum class SensorModel {
    kHdl64,  ///< Velodyne HDL-64E: 64 beams, an upper block of 32 from +2.0 to -8.33 degrees and a
             ///< lower block of 32 from -8.83 to -24.8 degrees; 1875 azimuth steps (0.192
             ///< degrees) per revolution, 120000 rays; 0.9-120 m; 10 Hz; on a car at 1.73 m
    kVlp16,  ///< Velodyne VLP-16: 16 beams from -15 to +15 degrees every 2 degrees in the
             ///< sensor's interleaved firing order; 1800 azimuth steps (0.2 degrees), 28800
             ///< rays; 0.5-100 m; 10 Hz; on a car at 1.73 m
    kTilt180,  ///< a 2-D line scanner (SICK LMS 200 type) nodding on a tilt unit, like the one
               ///< of the Kvarntorp mine data: 361 samples over 180 degrees (-90 to +90,
               ///< 0.5 degrees) in its scan plane, tilted from -40 to +50 degrees in 1 degree
               ///< steps (91 lines), 32851 rays, forward-facing only; 0.2-30 m; one 3-D scan
               ///< every 2 s; on a small robot at 0.6 m
    kHdl32,    ///< Velodyne HDL-32E: 32 beams from -30.67 to +10.67 degrees every 4/3 degrees in
               ///< the sensor's interleaved firing order (-30.67, -9.33, -29.33, -8.0, ...);
               ///< 2170 azimuth steps (0.166 degrees), 69440 rays (~695k points/s at 10 Hz);
               ///< 1-100 m; 10 Hz; on a car at 1.73 m
    kOuster64Wide,  ///< Ouster-like 64-beam scanner with a 90 degree vertical field: 64 beams
                    ///< uniformly from +45 to -45 degrees (1.43 degrees apart), fired together
                    ///< from the top down at each azimuth; 1024 azimuth steps (2048 possible),
                    ///< 65536 rays; 0.3-50 m (a short-range wide-field sensor); 10 Hz; on a
                    ///< car at 1.73 m. Not an exact product model.
    kLivoxAvia,     ///< Livox-Avia-like forward-looking non-repetitive scanner: 6 lasers trace a
                    ///< rosette (two counter-rotating prisms at incommensurate rates) over an
                    ///< elliptic field of 70.4 degrees horizontal by 77.2 degrees vertical around
                    ///< +x; the rosette keeps turning from scan to scan, so no two scans sample
                    ///< the same directions. 4000 samples per laser per scan, 24000 rays (240k
                    ///< points/s at 10 Hz); 1-190 m; 10 Hz; on a car at 1.73 m
};

std::string ToString(SensorModel model);
/// Parses "hdl64" / "vlp16" / "tilt180" / "hdl32" / "ouster64-wide" / "livox-avia"; throws
/// core::ConfigError listing the names.
SensorModel ParseSensorModel(std::string_view name);

/// What a scanner measures and how badly. Unset optional fields take the model's values (see
/// SensorModel).
struct SensorConfig {
    SensorModel model = SensorModel::kHdl64;
    double noise_m = 0.02;  ///< sigma of the Gaussian noise added to each range, >= 0
    double dropout = 0.02;  ///< probability that a return is lost, in [0, 1)
    /// Azimuth steps per revolution (hdl64, vlp16, hdl32, ouster64-wide), samples per scan line
    /// (tilt180) or samples per laser per scan (livox-avia), 1-20000.
    std::optional<int> horizontal_steps;
    std::optional<double> min_range_m;     ///< surfaces nearer than this give no point, >= 0
    std::optional<double> max_range_m;     ///< surfaces farther than this give no point
    std::optional<double> mount_height_m;  ///< sensor origin above the ground, (0, 20]
    std::optional<double> scan_period_s;   ///< time between scans, (0, 3600]

    /// Throws core::ConfigError naming the first invalid field ("sensor.dropout ...").
    void Validate() const;
};

/// A SensorConfig with every value resolved.
struct SensorSpec {
    SensorModel model = SensorModel::kHdl64;
    int beams = 64;  ///< lasers (spinning sensors, livox-avia) or tilt lines (tilt180)
    int horizontal_steps = 1875;
    double min_range_m = 0.9;
    double max_range_m = 120.0;
    double mount_height_m = 1.73;
    double scan_period_s = 0.1;
    double noise_m = 0.02;
    double dropout = 0.02;
};

/// Validates `config` and fills in the model's values for the unset fields.
SensorSpec Resolve(const SensorConfig& config);

/// True when every scan of `model` samples the same directions (all but livox-avia).
bool RepeatsEveryScan(SensorModel model);

/// Elevation angles of the beams (spinning sensors, in firing order) or the tilt angles of the
/// scan lines (tilt180), degrees, positive up; empty for livox-avia, whose lasers have no fixed
/// elevation.
std::vector<double> BeamElevationsDeg(SensorModel model);

/// The rays of scan `scan_index` as unit directions in the sensor frame, in the order the sensor
/// measures them: for the spinning sensors, every beam at each azimuth, the head turning
/// clockwise (seen from above) from straight back; for tilt180, each scan line from left to
/// right, lines from the lowest tilt up; for livox-avia, the 6 lasers at each sample time.
/// size() == beams * horizontal_steps. Only livox-avia depends on `scan_index`: its rosette
/// goes on turning where the previous scan left it.
std::vector<Eigen::Vector3d> BeamDirections(const SensorSpec& spec, std::size_t scan_index = 0);

}  // namespace lidarloop::sim

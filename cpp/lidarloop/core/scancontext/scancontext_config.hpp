#pragma once

namespace lidarloop::core {

/// The parameters of a Scan Context (Kim & Kim, IROS 2018): YAML section `scancontext`. Defaults
/// are the paper's (section IV: N_r = 20, N_s = 60, L_max = 80 m).
struct ScanContextConfig {
    int rings = 20;             ///< N_r, rings of equal radial width up to max_range_m; 1..200
    int sectors = 60;           ///< N_s, sectors of equal azimuth (6 degrees each); 6..720
    double max_range_m = 80.0;  ///< L_max, points at a planar range >= this are dropped
    /// Added to every point's z before binning, so that the ground under the sensor reads about
    /// 0 and structure positive: a bin holds max(0, max z + sensor_height_m), and a bin whose
    /// points all lie below that ground reads 0 like an empty one. 2 m: above the usual car
    /// mounts (KITTI's HDL-64E is at 1.73 m), so that the ground nearby stays >= 0.
    double sensor_height_m = 2.0;
    /// Retrieval: the number of scans whose ring keys are nearest to the query's (L2) that are
    /// then ranked by the full distance (the paper's two-stage search; at least top_k are taken).
    /// 0: no ring-key stage, every eligible scan is compared by the full distance (exact).
    int ring_key_candidates = 0;

    /// Throws ConfigError naming the first invalid field.
    void Validate() const;
    bool operator==(const ScanContextConfig&) const = default;
};

}  // namespace lidarloop::core

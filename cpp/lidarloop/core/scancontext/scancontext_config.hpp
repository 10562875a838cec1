#pragma once

#include "lidarloop/core/parameters.hpp"

namespace lidarloop::core {

/// The parameters of a Scan Context (Kim & Kim, IROS 2018): YAML section `scancontext`, flags
/// `--scancontext-<key>`, Python keywords of describe (docs/options.md). Defaults are the
/// paper's (section IV: N_r = 20, N_s = 60, L_max = 80 m).
struct ScanContextConfig {
    int rings = 20;             ///< N_r, rings of equal radial width up to max_range_m
    int sectors = 60;           ///< N_s, sectors of equal azimuth (6 degrees each)
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

    /// Every parameter, declared once (core/parameters.hpp): key, help, unit, valid range.
    template <typename Self, typename Visit>
    static void Declare(Self& c, Visit&& visit) {
        visit(c.rings, {"rings", "N_r, rings of equal width up to max_range_m", "", 1, 200});
        // At least 6 sectors: a sector spans less than 180 degrees, which the exact sector test
        // of the binning relies on.
        visit(c.sectors, {"sectors", "N_s, sectors of equal azimuth", "", 6, 720});
        visit(c.max_range_m, {"max_range_m", "L_max, farther points (planar range) are dropped",
                              "m", 0.1, 10'000.0});
        visit(c.sensor_height_m,
              {"sensor_height_m", "added to z, so that a bin holds max(0, z + this), metres", "m",
               -1'000.0, 1'000.0});
        visit(c.ring_key_candidates,
              {"ring_key_candidates",
               "scans of nearest ring key ranked by the full distance; 0: compare every scan", "",
               0, 1'000'000});
    }
    /// Throws ConfigError naming the first parameter outside its declared range.
    void Validate() const { CheckDeclaredRanges("scancontext", *this); }
    bool operator==(const ScanContextConfig&) const = default;
};

}  // namespace lidarloop::core

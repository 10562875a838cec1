#pragma once

namespace lidarloop::posegraph {

/// How much each edge is trusted: its information matrix (docs/posegraph.md).
///
/// Odometry: the step from scan i to i + 1 is a random walk in position and heading, its
/// variance growing with the distance l travelled in the step: sigma_t^2 = min_t^2 + a_t^2 l per
/// axis, sigma_r^2 = min_r^2 + a_r^2 l per rotation axis. The defaults (a_t = 0.1 m/sqrt(m),
/// a_r = 0.03 deg/sqrt(m)) are 1 m and 0.3 deg of drift (one sigma) over 100 m.
///
/// Loops: sigma_t = sqrt(loop_translation_sigma_m^2 + rmse^2) and loop_rotation_sigma_deg, the
/// information then scaled by clamp(overlap / loop_reference_overlap, 0.2, 2), with the
/// verification's RMS plane distance and smaller overlap fraction (unknown: rmse 0, overlap at
/// the reference).
struct InformationConfig {
    double odometry_translation_sigma_m_per_sqrt_m = 0.1;  ///< a_t, (0, 10]
    double odometry_rotation_sigma_deg_per_sqrt_m = 0.03;  ///< a_r, (0, 10]
    double odometry_min_translation_sigma_m = 0.01;        ///< min_t, (0, 10]
    double odometry_min_rotation_sigma_deg = 0.01;         ///< min_r, (0, 10]
    double loop_translation_sigma_m = 0.1;                 ///< (0, 100]
    double loop_rotation_sigma_deg = 0.5;                  ///< (0, 90]
    double loop_reference_overlap = 0.5;                   ///< (0, 1]

    bool operator==(const InformationConfig&) const = default;
};

/// How wrong loops are kept out (docs/posegraph.md#robustness).
struct RobustConfig {
    /// Odometry gate: a loop whose transform differs from the odometry's relative pose of its two
    /// scans by more than gate_sigmas times the odometry's drift over the path between them
    /// (the information model above), plus the minimum tolerances, is rejected before
    /// optimising. [1, 1000]
    double gate_sigmas = 5.0;
    double gate_min_translation_m = 3.0;  ///< [0, 1e4]
    double gate_min_rotation_deg = 10.0;  ///< [0, 180]
    /// Systematic drift the gate (and the support test) also allow, growing linearly with the
    /// path: per cent of it in translation, degrees per 100 m in rotation. [0, 100] each
    double gate_translation_percent = 3.0;
    double gate_rotation_deg_per_100m = 1.0;
    /// Support: a loop is checked against the loops whose two scans both lie within this path
    /// length of its own (m to m, q to q): the cycle of the two loops and the odometry between
    /// their ends must close within gate_sigmas times the odometry's drift over those short
    /// pieces and the two loops' own sigmas, plus the systematic allowance. Loops with fewer
    /// than min_support consistent neighbours are held out of the first optimisation and taken
    /// in only when the optimised graph agrees with them (reject_sigmas). When no loop has
    /// support (a single loop), all are optimised. (0, 1e4]
    double support_window_m = 30.0;
    int min_support = 1;  ///< [0, 1000]; 0: no support test
    /// Cauchy loss scale on loop edges in the last round, in sigmas of the loop's own
    /// information (whitened residual norm). (0, 100]
    double cauchy_scale = 2.0;
    /// After optimising, a loop whose whitened residual norm exceeds this is dropped and the
    /// graph optimised again without it. (0, 1000]
    double reject_sigmas = 5.0;
    /// Graduated rounds: the Cauchy scale starts at the median whitened residual of the gated
    /// loops at the odometry and is divided by this factor per round down to cauchy_scale.
    /// [1.5, 100]
    double scale_step = 8.0;
    int max_reject_rounds = 3;  ///< rounds of dropping loops and optimising again, [0, 100]

    bool operator==(const RobustConfig&) const = default;
};

/// Everything that decides the optimised trajectory (YAML section `posegraph`).
struct PoseGraphConfig {
    InformationConfig information;
    RobustConfig robust;
    /// Odometry whose position moves more than this between consecutive scans is an error naming
    /// the line (a jump or a reset), metres, (0, 1e8]. No vehicle a LiDAR rides on covers it at
    /// sensor rate: a car on a motorway (40 m/s) moves 4 m between scans at 10 Hz, a train at
    /// 360 km/h 10 m; 100 m still allows 1 Hz at that speed or skipped scans.
    double max_odometry_step_m = 100.0;
    /// Loops `optimise` takes from one scan's verified candidates when it detects them itself:
    /// the best (the scan's loop in loops.csv), then others whose match lies at least
    /// min_loop_separation_m of path from every match taken (an earlier pass of the place: more
    /// drift removed), up to max_loops_per_scan. [1, 100]; (0, 1e6] m
    int max_loops_per_scan = 3;
    double min_loop_separation_m = 50.0;
    int max_iterations = 50;  ///< Ceres (dogleg) iterations per solve, [1, 10000]
    int threads = 1;          ///< Ceres threads, [1, 256]

    /// Throws core::ConfigError naming the first invalid field ("posegraph.robust.gate_sigmas
    /// must be ...").
    void Validate() const;
    bool operator==(const PoseGraphConfig&) const = default;
};

}  // namespace lidarloop::posegraph

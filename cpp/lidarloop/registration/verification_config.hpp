#pragma once

namespace lidarloop::registration {

/// How a scan is reduced for registration (registration::PrepareScan). Ranges in metres from the
/// sensor origin, in the sensor frame (z up).
struct ScanReductionConfig {
    double min_range_m = 3.0;   ///< closer points are dropped (the vehicle itself), >= 0
    double max_range_m = 60.0;  ///< farther points are dropped; > min_range_m
    double voxel_m = 0.5;       ///< edge of the voxels the scan is averaged into, (0.05, 10]
    int normal_neighbors = 10;  ///< neighbours (voxel centroids) of a normal's PCA, 5..100
    /// A point is "structure" (distinguishes places) when its normal is at least this far from
    /// vertical, degrees: walls, poles, trunks, parked cars. The ground and roofs are not.
    double structure_min_tilt_deg = 45.0;
    /// Neighbours (voxel centroids, about 1.5 m around at 0.5 m voxels) that decide whether a
    /// structure point lies on a large plane, and the largest surface variation
    /// lambda0 / (lambda0 + lambda1 + lambda2) of such a plane.
    int distinctive_neighbors = 30;
    double max_plane_variation = 0.01;
    /// Structure points kept at most (a uniform subsample beyond), bounds registration time.
    int max_structure_points = 3000;
    /// Other points (mostly ground; they fix z, roll and pitch) kept at most.
    int max_ground_points = 600;
    /// Submaps (offline runs only): a scan is prepared merged with its neighbours within this
    /// much path on each side, metres, placed in its own frame (registration::PrepareSubmap) by
    /// the scans' odometry where given (never a dataset's own poses, which may be its ground
    /// truth), else by each scan's accepted registration to the one before
    /// (pipeline::PosesFromNeighbours); 0: each scan alone. One sparse scan holds too little
    /// structure to pin a pose; a few neighbours, placed with little drift, give it
    /// (docs/verification.md, "Submaps"). A sequence whose typical scan fills
    /// max_structure_points alone is verified alone (app::ScansFillTheStructureCap). [0, 100]
    double submap_path_m = 10.0;
    /// Neighbours per side at most, 0..1000: bounds the merge on a slow or standing platform.
    int submap_max_scans = 30;
    /// Raw points a submap merges at most, 10^4..10^8: the centre always, then its nearest
    /// neighbours in path while their points fit. The
    /// reduction caps what a scan keeps, so beyond a few dense scans more points cost time and
    /// add nothing; sparse scans fill the window (docs/verification.md, "Submaps").
    int submap_max_points = 600'000;

    /// Throws core::ConfigError naming the first invalid field (prefix "verification.").
    void Validate() const;
    bool operator==(const ScanReductionConfig&) const = default;
};

/// The coarse, prior-free alignment: a yaw search over top-down occupancy images of the
/// structure points, with an FFT cross-correlation for the translation at every yaw.
struct CoarseConfig {
    double cell_m = 1.5;              ///< edge of an image cell, metres, [0.1, 10]
    int grid_cells = 64;              ///< image edge in cells, a power of two in [16, 1024]
    double yaw_step_deg = 5.0;        ///< yaw search step, degrees, (0, 45]
    double max_translation_m = 25.0;  ///< largest planar offset searched, metres, > 0
    int hypotheses = 3;               ///< best (yaw, translation) peaks refined by ICP, 1..16
    /// A peak after the best is refined only when its coarse score reaches this share of the
    /// best's (the best's even when it is out of reach, max_peak_beyond_loop_m), [0, 1] (0: all
    /// `hypotheses`). On the real Livox and simulated sequences every pair accepted from a later
    /// peak had at least 0.87 of the best's score, and the ICP from the 2nd and 3rd peaks is
    /// most of the time of a rejected pair (docs/verification.md).
    double min_hypothesis_score_ratio = 0.8;
    /// A peak is refined only when it puts the two sensors at most AcceptanceConfig::
    /// max_loop_distance_m plus this far apart, metres, [0, 1000]: from farther it ends
    /// `too_far`. ICP moved accepted poses 0.2-2.1 m from their peak (medians), at most 7.8 m,
    /// and every accepted loop's peak lay within 12.5 m of the query on the gate sequences
    /// (docs/verification.md). Peaks out of this reach still count as rivals.
    double max_peak_beyond_loop_m = 6.0;
    /// Further peaks the ambiguity test registers after an acceptance (AcceptanceConfig::
    /// max_rival_overlap_ratio), 0..32: a repeating place fits as well elsewhere.
    int rival_hypotheses = 2;
    /// Translation peaks kept per yaw (3 cells apart at least), 1..8: repeating structure
    /// correlates at several offsets under one yaw.
    int peaks_per_yaw = 2;
    /// Where no odometry bounds the yaws, a pair's coarse search looks only within this many
    /// degrees of the yaw the two scans' layouts suggest and of that plus half a turn
    /// (registration::LayoutYaw), [1, 180]; 180: every yaw.
    double layout_yaw_window_deg = 15.0;
    /// The layouts leave the yaw open by half a turn: with this, the coarse search first
    /// correlates the yaw nearest each of the two centres and then searches only the window of
    /// the one that scores higher (both on a tie), about half the yaws. On the gate's runs
    /// without odometry the better centre was the accepted pose's half for all but 4 of 2,898
    /// accepted pairs (docs/verification.md, "The better half turn").
    bool better_half_turn_only = true;

    int TotalHypotheses() const { return hypotheses + rival_hypotheses; }
    void Validate() const;
    bool operator==(const CoarseConfig&) const = default;
};

/// Point-to-plane ICP from coarse to fine (registration::RefinePointToPlane).
struct IcpConfig {
    /// Largest correspondence distance of the first stage, metres; each further stage halves it
    /// down to `final_correspondence_m`.
    double initial_correspondence_m = 3.0;
    double final_correspondence_m = 0.6;  ///< > 0, <= initial
    int max_iterations_per_stage = 10;    ///< 1..100
    /// A stage ends when an iteration moves the pose by less than this (translation metres plus
    /// rotation radians).
    double convergence_step = 1e-3;
    /// Query points that ICP pairs, at most (an even subsample of the prepared scan's): the
    /// match side and the overlap measure keep every prepared point.
    int max_structure_points = 600;
    int max_ground_points = 200;
    /// Query points the first stage pairs, at most (and at most the two above), 10..10^6: at its
    /// wide correspondence distance the first stage only brings a pose into the basin of the
    /// right one, which a third of the points do as well; the later stages pair all of the
    /// above. Chosen on the urban HDL-64E and real HKU_1 replays, validated on fourteen gate
    /// sequences with and without odometry: the same loops at poses within 7 mm, one more real
    /// revisit, rejected pairs a fifth faster (docs/verification.md, "A thinner first stage").
    /// The ambiguity test's ICP pairs all of the above from its start.
    int first_stage_structure_points = 200;
    int first_stage_ground_points = 100;
    /// A hypothesis is abandoned after the first stage when its overlap (the share of structure
    /// points on the other scan's surfaces, AcceptanceConfig's measure, each way) is below this:
    /// measured on simulated urban and rural sequences, every pair that was finally accepted
    /// overlapped at least 0.24 there, most wrong pairs less than 0.15 (saves the later stages).
    double abandon_below_overlap = 0.15;
    /// Where no odometry judges the pose, a hypothesis is also abandoned after the first stage
    /// when it slides: shifted by AcceptanceConfig::degeneracy_shift_m along the direction its
    /// overlap constrains least, more than this share of the points facing that direction still
    /// fits (the degeneracy test's measure, on every 4th point; none facing it counts as all).
    /// On the gate's runs without odometry a pose sliding so after the first stage ended
    /// rejected in all but 1 of 14,863 cases, and their later stages were 15 % of ICP's
    /// iterations (docs/verification.md, "Poses that slide are dropped early").
    /// [AcceptanceConfig::max_shifted_overlap_ratio, 1]; 1: never.
    double abandon_above_shifted_overlap = 0.8;
    /// Longer steps along a sliding direction: when a step points within 37 degrees (cosine 0.8)
    /// of the previous one in the same stage, the pose moves 1 / (1 - r) times it, r the ratio of
    /// their lengths (where a series of such steps would end), at most this many times (Besl &
    /// McKay 1992's accelerated ICP, simplified). 1: plain Gauss-Newton steps, [1, 4]. Plain for
    /// the registration itself: longer steps carry wrong coarse peaks into partial fits that cost
    /// the later stages on real dense scans (docs/verification.md).
    double aligned_step_factor = 1.0;
    /// aligned_step_factor of the ambiguity test's ICP from the other peaks: a rival must be a
    /// pose ICP settles at, not one where it ran out of iterations sliding toward the accepted
    /// pose along a road. [1, 4].
    double rival_step_factor = 2.0;

    void Validate() const;
    bool operator==(const IcpConfig&) const = default;
};

/// Smallest |cosine| between the normals of two points that overlap (30 degrees): a wall point
/// does not overlap a pole that merely passes near it. Shared by the overlap test and a scan's
/// roughness (PreparedScan::structure_roughness_m), which must count pairs the same way.
inline constexpr float kOverlapMinNormalCosine = 0.866F;

/// When a registered candidate is accepted as a loop. Every value is physical: metres or a
/// fraction of points; docs/verification.md explains the rule.
struct AcceptanceConfig {
    /// A structure point of one scan overlaps when a structure point of the other scan lies within
    /// `overlap_radius_m` and its plane (match normal) passes within `overlap_plane_m`.
    double overlap_radius_m = 1.5;
    double overlap_plane_m = 0.3;
    /// Only points within this range of BOTH sensors count (what both could see), metres.
    double overlap_range_m = 40.0;
    /// Smallest overlap of structure points, each way (query -> match and match -> query).
    double min_overlap = 0.35;
    /// Smallest overlap of the distinctive structure points (not on large planes), each way:
    /// walls align in every street and corridor, the details of a place only at the place.
    /// Chosen on the demo sequence (right poses >= 0.40, wrong ones <= 0.20), validated on
    /// other scenes, sensors and the real KITTI loops (docs/verification.md).
    double min_distinctive_overlap = 0.3;
    /// Structure points that overlap, at least, each way: a handful of matched points proves
    /// nothing whatever the fraction. 60: chosen on an unseen rural drive (seed 7: 40 let two
    /// loops 1.9 m off through, 60 none), validated on the eight gate sequences (no new false or
    /// wrong-pose loop, rural +4 to +6 scans without odometry); 80 before (docs/BENCHMARK.md).
    int min_overlapping_points = 60;
    /// Fewer overlapping points suffice where the share is clearly over min_overlap: its lower
    /// bound at this many standard errors (Wilson) must reach it (EnoughOverlappingPoints), so
    /// the points asked for follow what the scans show in common. 2.5: chosen on the seed-7
    /// rural drives (at 2.0 a pose 6 m off passed the overlap test), validated on seed 11, the
    /// other gate sequences and the real ones (docs/BENCHMARK.md). 0: min_overlapping_points
    /// always.
    double overlap_confidence_z = 2.5;
    /// The RMS plane distance of the overlapping structure points may be at most this many
    /// times the scans' own roughness (PreparedScan::structure_roughness_m: how well each scan's
    /// points sit on their nearest neighbour's plane, the RMS of the two): a right alignment fits
    /// about as well as each scan fits itself, at any density and on any sensor (chosen on
    /// simulated sparse and dense sequences, validated on real ones: docs/verification.md).
    /// Clamped to [min_allowed_rmse_m, max_rmse_m] (noise-free input; a cap).
    double max_rmse_ratio = 1.0;
    /// The same ratio where the odometry judges the loop's pose (Verify's `allowed`). In open
    /// country the RMSE cannot tell right from wrong poses (vegetation fits anywhere along a road;
    /// right poses reach 1.9 x the roughness), and in towns the wrong poses it catches are the
    /// look-alike places the odometry's gate rejects. 1.25: chosen on the rural VLP-16 U-turn
    /// sequences, validated on the other gate sequences (docs/BENCHMARK.md). The ambiguity test
    /// keeps max_rmse_ratio: a rival must fit as well as a right pose in a town does.
    double max_rmse_ratio_with_odometry = 1.25;
    double min_allowed_rmse_m = 0.02;
    double max_rmse_m = 0.3;
    /// Degeneracy test: the overlapping points whose surfaces face the least-constrained
    /// horizontal direction must be at least `min_constraining_points`, and after shifting the
    /// solution by degeneracy_shift_m along that direction (both signs) at most
    /// `max_shifted_overlap_ratio` of them may still lie on a surface; else the geometry does
    /// not pin the position (a straight street, a corridor, an open field).
    int min_constraining_points = 20;
    /// The same floor where the odometry judges the loop's pose (Verify's `allowed`): its gate
    /// rejects a pose slid to a look-alike place beyond the drift, the shifted test one slid by a
    /// few metres, and 5 points are the fewest whose shifted share tells sliding from breaking
    /// (docs/verification.md, "The odometry pins the road").
    int min_constraining_points_with_odometry = 5;
    /// The same floor without odometry, offline, where the scans' own motion judges the loop:
    /// every scan from match to query registered to the one before (pipeline::CheckAgainstMotion
    /// then rejects a pose slid to a look-alike place farther than the chain allows, the shifted
    /// test one slid by a few metres). 5 as with the odometry; elsewhere min_constraining_points
    /// (docs/verification.md, "The scans' own motion pins the road").
    int min_constraining_points_with_motion = 5;
    double degeneracy_shift_m = 2.0;
    double max_shifted_overlap_ratio = 0.5;
    /// Ambiguity test: ICP from the other coarse hypotheses; a pose at least 1 m or 5 degrees
    /// from the accepted one whose overlap reaches this share of the accepted overlap (within
    /// the allowed RMSE) makes the place ambiguous: periodic structure, rows of trees, identical
    /// corridors.
    double max_rival_overlap_ratio = 0.8;
    /// A loop is a revisit of one place: the registered sensors at most this far apart (3-D),
    /// metres; the distance d of Röhling et al. that the evaluation's ground truth uses. Scans
    /// that register from farther apart see one street from two places (on a drive without
    /// revisits, the scans just outside the minimum gap); they are rejected as too far.
    double max_loop_distance_m = 10.0;
    /// Without odometry, a loop of a sequence (detect, evaluate, the online detector; not a
    /// single pair) must show at least this share of the distinctive overlap its scans show with
    /// their neighbours in the sequence (the lower of the two; pipeline::NeighbourOverlaps): a
    /// revisit fits about as well as the next scan does (ratio 0.51-1.03 on every simulated and
    /// real sequence measured), a look-alike place one block on fits a part (0.37-0.48 on the
    /// sparse towns; some reach 0.52-0.69 and pass). 0: off. Chosen on the seed-3 simulated
    /// drives and HKU, validated on seeds 7 and 11 and two seed-2 drives (docs/verification.md,
    /// "What the neighbours show").
    double min_neighbour_overlap_ratio = 0.5;
    /// With the odometry, offline (detect, evaluate, optimise): loops whose queries lie within
    /// this much path of each other, and their matches too, are neighbours, which the odometry
    /// relates over that short path; neighbours that agree form chains, and of two chains that
    /// disagree the shorter is rejected (pipeline::RejectLoopsUnlikeTheirRevisit). 0: off. 10 m:
    /// one place, the submaps' reach (docs/verification.md, "The loops of one revisit agree").
    double revisit_path_m = 10.0;
    /// Without odometry, offline (detect, evaluate; not the online detector), a loop of
    /// a sequence is also judged by the scans' own motion: the scans
    /// from its match to its query, each registered to the one before (pipeline::
    /// NeighbourOverlaps), chained. Where the chain never turns more than this from the match's
    /// heading (180: every chain), the loop is rejected when the chain puts the query farther
    /// from the match than max_loop_distance_m + motion_drift_m + motion_drift_ratio times the
    /// chain's path (pipeline::MotionRulesOutLoop). 0: off. Judging chains that turn too halved
    /// the gate's false loops without odometry (60 -> 31: look-alike crossings reached round a
    /// corner) and lost no true loop on the gate or validation sequences (at a drift ratio of 0.2
    /// then; a quarter of it lost 4 revisits; docs/verification.md, "The scans' own motion").
    /// Below 180 no pair gets min_constraining_points_with_motion: a chain may turn unjudged.
    double motion_max_turn_deg = 180.0;
    double motion_drift_m = 3.0;  ///< what the chain may be off by besides its share, metres
    /// and this share of its path. 0.1: chosen on the gate sequences (0.2 let two look-alike
    /// crossings of the urban HDL-64E grid through once the motion's degeneracy floor let them
    /// register), validated on unseen rural seeds 15-18 (5 false loops -> 1, no revisit lost);
    /// every true loop measured stays at least 7.8 m inside it, real HKU_1 included
    /// (docs/verification.md, "The drift a chain may have").
    double motion_drift_ratio = 0.1;

    void Validate() const;
    bool operator==(const AcceptanceConfig&) const = default;
};

/// Geometric verification of loop candidates: everything registration::Verify needs.
struct VerificationConfig {
    ScanReductionConfig reduction;
    CoarseConfig coarse;
    IcpConfig icp;
    AcceptanceConfig acceptance;

    void Validate() const;
    bool operator==(const VerificationConfig&) const = default;
};

}  // namespace lidarloop::registration

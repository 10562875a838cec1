#pragma once

#include <vector>

#include "lidarloop/core/parameters.hpp"

namespace lidarloop::core {

/// Parameters of the NDT appearance descriptor (Magnusson et al. 2009, section II-E). Defaults
/// are the paper's, except where a comment says otherwise. The decision threshold t_d is not a
/// descriptor parameter (detection.threshold).
struct NdtConfig {
    static constexpr char kSection[] = "ndt";  ///< YAML section

    double cell_size_m = 0.5;  ///< q, side of an NDT cell; cell corners are q/2 apart
    /// Cells with fewer points are not classified. The paper does not state its minimum; 5 is
    /// the smallest count whose 3x3 covariance is not dominated by sampling noise for planes.
    int min_points_per_cell = 5;
    double eigen_ratio_threshold = 0.10;  ///< t_e: linear if l2/l1 < t_e, planar if l3/l2 < t_e
    int spherical_classes = 1;            ///< s, sub-classes by l2/l1 over [t_e, 1]
    int planar_classes = 9;               ///< p, sub-classes by the line of the normal e3
    int linear_classes = 1;               ///< l, sub-classes by the line of the axis e1
    /// Borders of the range intervals R, metres from the sensor to the cell mean; the paper's
    /// {[0,3), [3,6), [6,9), [9,15), [15,inf)}.
    std::vector<double> range_limits_m = {3.0, 6.0, 9.0, 15.0};
    /// Section II-C: align the scan by the peaks of its planar cells' orientations (and, for a
    /// second direction, of its linear cells' when l > 1); a second direction within 20 degrees
    /// of the first sets no yaw. The planar classes steer it, so with p = 0 there is nothing to
    /// align by and the descriptor is unrotated, whatever l is. false gives one unrotated
    /// descriptor.
    bool normalise_rotation = true;
    double ambiguity_ratio = 0.60;  ///< t_a, peaks >= t_a * the highest are ambiguous
    /// true: the peaks of eqs. (4)-(7) are the modes of the cells' normals (mean shift with a
    /// 20-degree window, core/ndt/ndt_orientation_modes.hpp), counted by the cells within 20
    /// degrees of each; they turn with the scan, so a rotated scan gets the same peaks, and a
    /// surface is never split in two by a class border. false: the peaks are the classes of the
    /// partition, each aligned by its line P_i, as the paper writes; which surfaces share a class
    /// (~40 degrees wide for p = 9) then depends on how the scan is turned, and a rotated scan can
    /// get other peaks and a different descriptor.
    bool align_to_mean_direction = true;
    /// false: count each rotation candidate by rotating the cells' axes (one grid per scan).
    /// true: rotate the points and build a new axis-aligned grid per candidate, as the paper
    /// does; slower. Either way a rotated or moved scan falls differently into its grid, so
    /// sigma' between a scan and its rotated copy is as small as that discretisation allows
    /// (about that of a translation by a fraction of a cell), not zero.
    bool regrid_rotations = false;

    /// Every parameter, declared once (core/parameters.hpp): key, help, unit, valid range.
    /// range_limits_m and the total of classes are checked by Validate.
    template <typename Self, typename Visit>
    static void Declare(Self& c, Visit&& visit) {
        visit(c.cell_size_m,
              {"cell_size_m", "q, side of an NDT cell; cells overlap by q/2", "m", 0.01, 100.0});
        // A cell's shape needs at least 3 points.
        visit(c.min_points_per_cell,
              {"min_points_per_cell", "sparser cells are not classified", "", 3, 1'000'000});
        visit(c.eigen_ratio_threshold,
              {"eigen_ratio_threshold", "t_e of the shape classes", "", 0.0, 1.0, true});
        visit(c.spherical_classes, {"spherical_classes", "s, sub-classes by l2/l1", "", 0, 100});
        visit(c.planar_classes,
              {"planar_classes", "p, sub-classes by normal orientation", "", 0, 10'000});
        visit(c.linear_classes,
              {"linear_classes", "l, sub-classes by axis orientation", "", 0, 10'000});
        visit(c.range_limits_m, {"range_limits_m", "borders of the range intervals", "m"});
        visit(c.normalise_rotation,
              {"normalise_rotation", "align dominant planes (section II-C)", ""});
        visit(c.ambiguity_ratio,
              {"ambiguity_ratio", "t_a, peaks this close are ambiguous", "", 0.0, 1.0});
        visit(c.align_to_mean_direction,
              {"align_to_mean_direction",
               "peaks are modes of the cells' normals (true) or partition classes, lines P_i "
               "(false)",
               ""});
        visit(c.regrid_rotations,
              {"regrid_rotations", "new grid per rotation (paper) vs rotated cells", ""});
    }
    int FeatureCount() const { return spherical_classes + planar_classes + linear_classes; }
    int RangeCount() const { return static_cast<int>(range_limits_m.size()) + 1; }
    /// Throws ConfigError naming the first invalid field.
    void Validate() const;
    bool operator==(const NdtConfig&) const = default;
};

}  // namespace lidarloop::core

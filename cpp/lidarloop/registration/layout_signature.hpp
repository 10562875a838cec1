#pragma once

#include <vector>

#include <Eigen/Core>

#include "lidarloop/registration/coarse_alignment.hpp"

namespace lidarloop::registration {

/// A scan's layout seen from above, wherever in it the sensor stood: the magnitudes of the 2-D
/// Fourier transform of its top-down structure image (the coarse search's image at its default
/// geometry: 64 x 64 cells of 1.5 m), sampled on a polar grid of spatial frequencies (radii 2 to
/// 15 cycles per image, 36 angles over half a turn, 5 degrees apart), as log(1 + |F|) with zero
/// mean and unit norm. A translation changes only the transform's phase; a yaw turns the
/// magnitudes, a circular shift in angle (the magnitudes of a real image repeat after half a
/// turn). The geometry is fixed, not the run's coarse config, so that the signatures of a saved
/// map compare with new ones. It orders a query's shortlist before registration where no
/// odometry does (docs/verification.md, "The layout orders the shortlist").
struct LayoutSignature {
    static constexpr int kRadii = 14;
    static constexpr int kAngles = 36;
    /// values[r * kAngles + a]; empty for a scan without structure.
    std::vector<float> values;

    bool empty() const { return values.empty(); }
};

/// The signature of the structure points (sensor frame, metres) of a prepared scan.
LayoutSignature ComputeLayoutSignature(const std::vector<Eigen::Vector3f>& structure_points);

/// How alike two layouts are: the largest correlation of the signatures over their angle shifts
/// (every yaw), in [-1, 1]; NaN when either is empty.
double LayoutSimilarity(const LayoutSignature& a, const LayoutSignature& b);

/// The yaw of T_match_query (radians, in [0, pi)) that turns `query`'s layout onto `match`'s: the
/// angle shift of LayoutSimilarity's largest correlation, refined between the 5-degree shifts by
/// a parabola. The magnitudes repeat after half a turn, so the loop's yaw is this or this plus
/// pi. NaN when either is empty.
double LayoutYaw(const LayoutSignature& query, const LayoutSignature& match);

/// The yaws of T_match_query a pair's coarse search looks at where no odometry bounds them:
/// within config.layout_yaw_window_deg of LayoutYaw and of that plus half a turn; every yaw where
/// either layout is empty (docs/verification.md, "The layouts bound the yaw search").
YawWindow LayoutYawWindow(const LayoutSignature& query, const LayoutSignature& match,
                          const CoarseConfig& config);

}  // namespace lidarloop::registration

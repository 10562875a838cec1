#include "lidarloop/registration/verification_config.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"

namespace lidarloop::registration {
namespace {

// Finite and within [low, high]; NaN fails every comparison, so test it explicitly.
void RequireIn(double value, double low, double high, const std::string& field) {
    if (!std::isfinite(value) || value < low || value > high) {
        throw core::ConfigError("verification." + field + " must be in [" + core::NumberText(low) +
                                ", " + core::NumberText(high) + "], got " +
                                core::NumberText(value));
    }
}

void RequireIn(int value, int low, int high, const std::string& field) {
    if (value < low || value > high) {
        throw core::ConfigError("verification." + field + " must be in [" + std::to_string(low) +
                                ", " + std::to_string(high) + "], got " + std::to_string(value));
    }
}

}  // namespace

void ScanReductionConfig::Validate() const {
    RequireIn(min_range_m, 0.0, 1000.0, "reduction.min_range_m");
    RequireIn(max_range_m, min_range_m + 1e-3, 1000.0, "reduction.max_range_m");
    RequireIn(voxel_m, 0.05, 10.0, "reduction.voxel_m");
    RequireIn(normal_neighbors, 5, 100, "reduction.normal_neighbors");
    RequireIn(structure_min_tilt_deg, 0.0, 90.0, "reduction.structure_min_tilt_deg");
    RequireIn(distinctive_neighbors, 5, 500, "reduction.distinctive_neighbors");
    RequireIn(max_plane_variation, 0.0, 1.0 / 3.0, "reduction.max_plane_variation");
    RequireIn(max_structure_points, 10, 1'000'000, "reduction.max_structure_points");
    RequireIn(max_ground_points, 10, 1'000'000, "reduction.max_ground_points");
    RequireIn(submap_path_m, 0.0, 100.0, "reduction.submap_path_m");
    RequireIn(submap_max_scans, 0, 1000, "reduction.submap_max_scans");
    RequireIn(submap_max_points, 10'000, 100'000'000, "reduction.submap_max_points");
}

void CoarseConfig::Validate() const {
    RequireIn(cell_m, 0.1, 10.0, "coarse.cell_m");
    RequireIn(grid_cells, 16, 1024, "coarse.grid_cells");
    if ((grid_cells & (grid_cells - 1)) != 0) {
        throw core::ConfigError("verification.coarse.grid_cells must be a power of two");
    }
    RequireIn(yaw_step_deg, 0.1, 45.0, "coarse.yaw_step_deg");
    RequireIn(max_translation_m, 0.1, 1000.0, "coarse.max_translation_m");
    RequireIn(hypotheses, 1, 16, "coarse.hypotheses");
    RequireIn(min_hypothesis_score_ratio, 0.0, 1.0, "coarse.min_hypothesis_score_ratio");
    RequireIn(max_peak_beyond_loop_m, 0.0, 1000.0, "coarse.max_peak_beyond_loop_m");
    RequireIn(rival_hypotheses, 0, 32, "coarse.rival_hypotheses");
    RequireIn(peaks_per_yaw, 1, 8, "coarse.peaks_per_yaw");
    RequireIn(layout_yaw_window_deg, 1.0, 180.0, "coarse.layout_yaw_window_deg");
}

void IcpConfig::Validate() const {
    RequireIn(initial_correspondence_m, 0.01, 100.0, "icp.initial_correspondence_m");
    RequireIn(final_correspondence_m, 0.01, initial_correspondence_m, "icp.final_correspondence_m");
    RequireIn(max_iterations_per_stage, 1, 100, "icp.max_iterations_per_stage");
    RequireIn(convergence_step, 1e-9, 1.0, "icp.convergence_step");
    RequireIn(max_structure_points, 10, 1'000'000, "icp.max_structure_points");
    RequireIn(max_ground_points, 10, 1'000'000, "icp.max_ground_points");
    RequireIn(first_stage_structure_points, 10, 1'000'000, "icp.first_stage_structure_points");
    RequireIn(first_stage_ground_points, 10, 1'000'000, "icp.first_stage_ground_points");
    RequireIn(abandon_below_overlap, 0.0, 1.0, "icp.abandon_below_overlap");
    RequireIn(abandon_above_shifted_overlap, 0.0, 1.0, "icp.abandon_above_shifted_overlap");
    RequireIn(aligned_step_factor, 1.0, 4.0, "icp.aligned_step_factor");
    RequireIn(rival_step_factor, 1.0, 4.0, "icp.rival_step_factor");
}

void AcceptanceConfig::Validate() const {
    RequireIn(overlap_radius_m, 0.01, 100.0, "acceptance.overlap_radius_m");
    RequireIn(overlap_plane_m, 0.001, overlap_radius_m, "acceptance.overlap_plane_m");
    RequireIn(overlap_range_m, 1.0, 1000.0, "acceptance.overlap_range_m");
    RequireIn(min_overlap, 0.0, 1.0, "acceptance.min_overlap");
    RequireIn(min_distinctive_overlap, 0.0, 1.0, "acceptance.min_distinctive_overlap");
    RequireIn(min_overlapping_points, 1, 1'000'000, "acceptance.min_overlapping_points");
    RequireIn(overlap_confidence_z, 0.0, 10.0, "acceptance.overlap_confidence_z");
    RequireIn(max_rmse_ratio, 0.0, 1000.0, "acceptance.max_rmse_ratio");
    RequireIn(max_rmse_ratio_with_odometry, 0.0, 1000.0, "acceptance.max_rmse_ratio_with_odometry");
    RequireIn(min_allowed_rmse_m, 0.0, 100.0, "acceptance.min_allowed_rmse_m");
    RequireIn(max_rmse_m, std::max(0.001, min_allowed_rmse_m), 100.0, "acceptance.max_rmse_m");
    RequireIn(min_constraining_points, 1, 1'000'000, "acceptance.min_constraining_points");
    RequireIn(min_constraining_points_with_odometry, 1, 1'000'000,
              "acceptance.min_constraining_points_with_odometry");
    RequireIn(min_constraining_points_with_motion, 1, 1'000'000,
              "acceptance.min_constraining_points_with_motion");
    RequireIn(degeneracy_shift_m, 0.0, 100.0, "acceptance.degeneracy_shift_m");
    RequireIn(max_shifted_overlap_ratio, 0.0, 1.0, "acceptance.max_shifted_overlap_ratio");
    RequireIn(max_rival_overlap_ratio, 0.0, 10.0, "acceptance.max_rival_overlap_ratio");
    RequireIn(max_loop_distance_m, 0.1, 1e4, "acceptance.max_loop_distance_m");
    RequireIn(min_neighbour_overlap_ratio, 0.0, 10.0, "acceptance.min_neighbour_overlap_ratio");
    RequireIn(revisit_path_m, 0.0, 1e4, "acceptance.revisit_path_m");
    RequireIn(motion_max_turn_deg, 0.0, 180.0, "acceptance.motion_max_turn_deg");
    RequireIn(motion_drift_m, 0.0, 1e4, "acceptance.motion_drift_m");
    RequireIn(motion_drift_ratio, 0.0, 10.0, "acceptance.motion_drift_ratio");
}

void VerificationConfig::Validate() const {
    reduction.Validate();
    coarse.Validate();
    icp.Validate();
    acceptance.Validate();
    // Below the acceptance's own bar the check would drop poses the degeneracy test passes.
    RequireIn(icp.abandon_above_shifted_overlap, acceptance.max_shifted_overlap_ratio, 1.0,
              "icp.abandon_above_shifted_overlap (at least acceptance.max_shifted_overlap_ratio)");
}

}  // namespace lidarloop::registration

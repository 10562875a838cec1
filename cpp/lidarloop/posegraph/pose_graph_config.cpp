#include "lidarloop/posegraph/pose_graph_config.hpp"

#include <cmath>
#include <string>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"

namespace lidarloop::posegraph {
namespace {

// (low, high] when open_low, else [low, high]; NaN fails every comparison.
void Require(double value, double low, double high, bool open_low, const std::string& field) {
    const bool above = open_low ? value > low : value >= low;
    if (!std::isfinite(value) || !above || value > high) {
        throw core::ConfigError("posegraph." + field + " must be in " + (open_low ? "(" : "[") +
                                core::NumberText(low) + ", " + core::NumberText(high) + "], got " +
                                core::NumberText(value));
    }
}

void Require(int value, int low, int high, const std::string& field) {
    if (value < low || value > high) {
        throw core::ConfigError("posegraph." + field + " must be in [" + std::to_string(low) +
                                ", " + std::to_string(high) + "], got " + std::to_string(value));
    }
}

}  // namespace

void PoseGraphConfig::Validate() const {
    const InformationConfig& i = information;
    Require(i.odometry_translation_sigma_m_per_sqrt_m, 0.0, 10.0, true,
            "information.odometry_translation_sigma_m_per_sqrt_m");
    Require(i.odometry_rotation_sigma_deg_per_sqrt_m, 0.0, 10.0, true,
            "information.odometry_rotation_sigma_deg_per_sqrt_m");
    Require(i.odometry_min_translation_sigma_m, 0.0, 10.0, true,
            "information.odometry_min_translation_sigma_m");
    Require(i.odometry_min_rotation_sigma_deg, 0.0, 10.0, true,
            "information.odometry_min_rotation_sigma_deg");
    Require(i.loop_translation_sigma_m, 0.0, 100.0, true, "information.loop_translation_sigma_m");
    Require(i.loop_rotation_sigma_deg, 0.0, 90.0, true, "information.loop_rotation_sigma_deg");
    Require(i.loop_reference_overlap, 0.0, 1.0, true, "information.loop_reference_overlap");
    const RobustConfig& r = robust;
    Require(r.gate_sigmas, 1.0, 1000.0, false, "robust.gate_sigmas");
    Require(r.gate_min_translation_m, 0.0, 1e4, false, "robust.gate_min_translation_m");
    Require(r.gate_min_rotation_deg, 0.0, 180.0, false, "robust.gate_min_rotation_deg");
    Require(r.gate_translation_percent, 0.0, 100.0, false, "robust.gate_translation_percent");
    Require(r.gate_rotation_deg_per_100m, 0.0, 100.0, false, "robust.gate_rotation_deg_per_100m");
    Require(r.support_window_m, 0.0, 1e4, true, "robust.support_window_m");
    Require(r.min_support, 0, 1000, "robust.min_support");
    Require(r.cauchy_scale, 0.0, 100.0, true, "robust.cauchy_scale");
    Require(r.reject_sigmas, 0.0, 1000.0, true, "robust.reject_sigmas");
    Require(r.scale_step, 1.5, 100.0, false, "robust.scale_step");
    Require(r.max_reject_rounds, 0, 100, "robust.max_reject_rounds");
    Require(max_odometry_step_m, 0.0, 1e8, true, "max_odometry_step_m");
    Require(max_loops_per_scan, 1, 100, "max_loops_per_scan");
    Require(min_loop_separation_m, 0.0, 1e6, true, "min_loop_separation_m");
    Require(max_iterations, 1, 10000, "max_iterations");
    Require(threads, 1, 256, "threads");
}

}  // namespace lidarloop::posegraph

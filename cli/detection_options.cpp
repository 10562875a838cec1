#include "detection_options.hpp"

#include "lidarloop/core/min_gap.hpp"

namespace lidarloop::cli {

void DetectionOptions::AddTo(CLI::App& command, bool decides_loops,
                             const std::string& min_gap_help) {
    min_gap_option_ = command.add_option("--min-gap", min_gap_, min_gap_help);
    command.add_option(
        "--min-gap-unit", min_gap_unit_,
        "unit of --min-gap: scans | seconds | metres (of path, from the poses or odometry)");
    if (!decides_loops) return;
    threshold_option_ = command.add_option(
        "--threshold", threshold_,
        "tau (height, range), t_d (ndt) or d (scancontext); default from the config");
    top_k_option_ = command.add_option("--top-k", top_k_, "candidates per query scan");
    command.add_flag("--no-verify", no_verify_,
                     "descriptor only: accept by the threshold, no geometric verification");
}

void DetectionOptions::ApplyTo(io::RunConfig& config) const {
    if (threshold_option_ != nullptr && *threshold_option_) config.detection.threshold = threshold_;
    if (*min_gap_option_) config.detection.min_gap.value = min_gap_;
    if (!min_gap_unit_.empty())
        config.detection.min_gap.unit = core::ParseMinGapUnit(min_gap_unit_);
    if (top_k_option_ != nullptr && *top_k_option_) config.detection.top_k = top_k_;
    if (no_verify_) config.detection.verify = false;
    config.Validate();
}

}  // namespace lidarloop::cli

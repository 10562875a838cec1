#pragma once

#include <cstddef>
#include <functional>

#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/registration/prepared_scan.hpp"
#include "lidarloop/registration/verification_config.hpp"

namespace lidarloop::registration {

/// The outcome of RefinePointToPlane.
struct IcpResult {
    core::Transform T_match_query = core::Transform::Identity();
    bool converged = false;           ///< the last stage settled (a step below convergence_step)
    int iterations = 0;               ///< over all stages
    std::size_t correspondences = 0;  ///< of the last iteration
    /// Share of the paired query structure points whose plane distance was within
    /// final_correspondence_m in the last iteration.
    double structure_inliers = 0.0;
    bool abandoned = false;  ///< stopped after the first stage (`keep_going` said no)
};

/// Point-to-plane ICP of the query onto the match, from `T_initial` (T_match_query), with the
/// correspondence distance shrinking stage by stage (coarse to fine). Structure points pair only
/// with structure points, ground with ground; residuals are distances to the match's planes,
/// weighted robustly. When finer stages follow, the first stage pairs at most IcpConfig::
/// first_stage_*_points of the query's points and the others max_*_points. After the first stage,
/// `keep_going(T_match_query)` (when given) decides whether the later stages run; when it says no,
/// the result is abandoned. Thread-safe.
IcpResult RefinePointToPlane(const PreparedScan& query, const PreparedScan& match,
                             const core::Transform& T_initial, const IcpConfig& config,
                             const std::function<bool(const core::Transform&)>& keep_going = {});

}  // namespace lidarloop::registration

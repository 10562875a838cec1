#include "registration/open3d_oracle.hpp"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/CorrespondenceChecker.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/pipelines/registration/GeneralizedICP.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <open3d/utility/Random.h>

#include "lidarloop/core/error.hpp"

namespace lidarloop::test {
namespace {

namespace o3d_geometry = open3d::geometry;
namespace o3d_registration = open3d::pipelines::registration;

void Require(bool condition, const std::string& message) {
    if (!condition) throw core::ConfigError("Open3dOracleConfig: " + message);
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Sets OpenMP's thread count of the calling thread for the guard's lifetime. Open3D's parallel
// loops run on libgomp, which reads it from the thread that enters them.
class OmpThreadsGuard {
public:
    explicit OmpThreadsGuard(int threads) : saved_(omp_get_max_threads()) {
        omp_set_num_threads(threads);
    }
    ~OmpThreadsGuard() { omp_set_num_threads(saved_); }
    OmpThreadsGuard(const OmpThreadsGuard&) = delete;
    OmpThreadsGuard& operator=(const OmpThreadsGuard&) = delete;

private:
    int saved_;
};

// The finite points of `cloud` within [min_range_m, max_range_m] of the sensor, in double.
o3d_geometry::PointCloud ToOpen3d(const core::PointCloud& cloud, const Open3dOracleConfig& config,
                                  const char* which) {
    const double max_range_m = config.max_range_m > 0.0 ? config.max_range_m : INFINITY;
    o3d_geometry::PointCloud out;
    out.points_.reserve(cloud.size());
    for (const Eigen::Vector3f& p : cloud) {
        if (!p.allFinite()) continue;
        const double range_m = p.cast<double>().norm();
        if (range_m >= config.min_range_m && range_m <= max_range_m)
            out.points_.push_back(p.cast<double>());
    }
    if (out.points_.size() < 3) {
        throw core::EmptyInputError(std::string("RegisterWithOpen3d: the ") + which + " scan has " +
                                    std::to_string(out.points_.size()) +
                                    " finite points within the range limits; 3 are needed");
    }
    return out;
}

// A voxel grid of `cloud` with normals that point to the sensor at the origin. A consistent
// orientation matters for FPFH, whose angles flip sign with the normals; a LiDAR sees every
// surface from the sensor's side.
std::shared_ptr<o3d_geometry::PointCloud> Downsample(const o3d_geometry::PointCloud& cloud,
                                                     double voxel_m,
                                                     const Open3dOracleConfig& config) {
    auto down = cloud.VoxelDownSample(voxel_m);
    down->EstimateNormals(o3d_geometry::KDTreeSearchParamHybrid(config.normal_radius_m,
                                                                config.normal_max_neighbours));
    down->OrientNormalsTowardsCameraLocation(Eigen::Vector3d::Zero());
    return down;
}

}  // namespace

void Open3dOracleConfig::Validate() const {
    Require(std::isfinite(min_range_m) && min_range_m >= 0.0, "min_range_m must be >= 0");
    Require(std::isfinite(max_range_m) && (max_range_m == 0.0 || max_range_m > min_range_m),
            "max_range_m must be 0 (no limit) or > min_range_m");
    Require(voxel_m > 0.05 && voxel_m <= 5.0, "voxel_m must be in (0.05, 5]");
    Require(normal_radius_m > 0.0 && normal_radius_m <= 50.0, "normal_radius_m must be in (0, 50]");
    Require(normal_max_neighbours >= 3, "normal_max_neighbours must be >= 3");
    Require(feature_radius_m > 0.0 && feature_radius_m <= 100.0,
            "feature_radius_m must be in (0, 100]");
    Require(feature_max_neighbours >= 3, "feature_max_neighbours must be >= 3");
    Require(ransac_distance_m > 0.0 && ransac_distance_m <= 50.0,
            "ransac_distance_m must be in (0, 50]");
    Require(edge_length_similarity > 0.0 && edge_length_similarity < 1.0,
            "edge_length_similarity must be in (0, 1)");
    Require(ransac_max_iterations >= 1, "ransac_max_iterations must be >= 1");
    Require(ransac_confidence > 0.0 && ransac_confidence <= 1.0,
            "ransac_confidence must be in (0, 1]");
    Require(refine_voxel_m > 0.01 && refine_voxel_m <= voxel_m,
            "refine_voxel_m must be in (0.01, voxel_m]");
    Require(refine_distance_m > 0.0 && refine_distance_m <= 50.0,
            "refine_distance_m must be in (0, 50]");
    Require(refine_max_iterations >= 1, "refine_max_iterations must be >= 1");
    Require(seed <= 0x7fffffffu, "seed must fit an int (Open3D's Seed takes an int)");
}

Open3dRegistration RegisterWithOpen3d(const core::PointCloud& query, const core::PointCloud& match,
                                      const Open3dOracleConfig& config) {
    config.Validate();
    Open3dRegistration result;
    auto start = std::chrono::steady_clock::now();
    const o3d_geometry::PointCloud query_full = ToOpen3d(query, config, "query");
    const o3d_geometry::PointCloud match_full = ToOpen3d(match, config, "match");
    const auto query_down = Downsample(query_full, config.voxel_m, config);
    const auto match_down = Downsample(match_full, config.voxel_m, config);
    const o3d_geometry::KDTreeSearchParamHybrid feature_search(config.feature_radius_m,
                                                               config.feature_max_neighbours);
    const auto query_fpfh = o3d_registration::ComputeFPFHFeature(*query_down, feature_search);
    const auto match_fpfh = o3d_registration::ComputeFPFHFeature(*match_down, feature_search);
    result.query_points = query_down->points_.size();
    result.match_points = match_down->points_.size();
    result.times.features_s = SecondsSince(start);

    start = std::chrono::steady_clock::now();
    const o3d_registration::CorrespondenceCheckerBasedOnEdgeLength edge_checker(
        config.edge_length_similarity);
    const o3d_registration::CorrespondenceCheckerBasedOnDistance distance_checker(
        config.ransac_distance_m);
    o3d_registration::RegistrationResult global;
    {
        // One thread: RANSAC's threads draw from Open3D's one global engine under a mutex, so
        // with more than one the samples each hypothesis gets depend on timing.
        const OmpThreadsGuard one_thread(1);
        open3d::utility::random::Seed(static_cast<int>(config.seed));
        global = o3d_registration::RegistrationRANSACBasedOnFeatureMatching(
            *query_down, *match_down, *query_fpfh, *match_fpfh, /*mutual_filter=*/true,
            config.ransac_distance_m, o3d_registration::TransformationEstimationPointToPoint(false),
            /*ransac_n=*/3, {std::cref(edge_checker), std::cref(distance_checker)},
            o3d_registration::RANSACConvergenceCriteria(config.ransac_max_iterations,
                                                        config.ransac_confidence));
    }
    result.ransac_fitness = global.fitness_;
    result.ransac_inliers = global.correspondence_set_.size();
    result.times.ransac_s = SecondsSince(start);

    start = std::chrono::steady_clock::now();
    const auto query_fine = Downsample(query_full, config.refine_voxel_m, config);
    const auto match_fine = Downsample(match_full, config.refine_voxel_m, config);
    const o3d_registration::ICPConvergenceCriteria criteria(1e-6, 1e-6,
                                                            config.refine_max_iterations);
    const o3d_registration::RegistrationResult refined =
        config.refinement == Open3dRefinement::kGeneralizedIcp
            ? o3d_registration::RegistrationGeneralizedICP(
                  *query_fine, *match_fine, config.refine_distance_m, global.transformation_,
                  o3d_registration::TransformationEstimationForGeneralizedICP(), criteria)
            : o3d_registration::RegistrationICP(
                  *query_fine, *match_fine, config.refine_distance_m, global.transformation_,
                  o3d_registration::TransformationEstimationPointToPlane(), criteria);
    result.times.refine_s = SecondsSince(start);

    result.T_match_query.matrix() = refined.transformation_;
    result.fitness = refined.fitness_;
    result.rmse_m = refined.inlier_rmse_;
    return result;
}

}  // namespace lidarloop::test

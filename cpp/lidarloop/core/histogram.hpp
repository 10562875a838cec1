#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/core/parameters.hpp"
#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/core/projection.hpp"

namespace lidarloop::core {

/// What to do with a point whose value v(p) lies outside [v_min, v_max].
///
/// Röhling eq. (4) divides the count of each bucket by |S|, all points of the scan, and section
/// III-C relies on sum_k h_k = 1. Both hold together only when every value falls into some
/// bucket, so the paper implies clamping: out-of-range values join the end buckets and every
/// point is counted. kDrop is offered for users who prefer to ignore far or odd points; it
/// normalises by the points kept so that the histogram still sums to 1.
enum class OutOfRangePolicy { kClamp, kDrop };

std::string ToString(OutOfRangePolicy policy);
OutOfRangePolicy ParseOutOfRangePolicy(std::string_view name);

/// Parameters of the LiDAR histograms (Röhling et al. 2015, section III). The paper states no
/// bucket count or value range; the defaults below are lidarloop's choices for a car-mounted
/// 360° LiDAR (10 cm height buckets, 0.8 m range buckets). The decision threshold tau is not a
/// descriptor parameter (detection.threshold); it depends on b and on the value range, so learn it
/// on your data (`lidarloop evaluate`) when you change them.
struct HistogramConfig {
    static constexpr char kSection[] = "histogram";  ///< YAML section, shared by height and range

    int bins = 100;                                 ///< b, number of buckets
    UpVectorMode up_vector = UpVectorMode::kFixed;  ///< up vector of the height projection
    /// Added to <p, u> so that 0 is the ground (Röhling footnote 1: the plane of the height
    /// projection passes through the sensor). 0 keeps heights relative to the sensor.
    double sensor_height_m = 0.0;
    double height_min_m = -3.0;  ///< v_min of the height projection
    double height_max_m = 7.0;   ///< v_max of the height projection
    double range_min_m = 0.0;    ///< v_min of the range projection
    double range_max_m = 80.0;   ///< v_max of the range projection
    OutOfRangePolicy out_of_range = OutOfRangePolicy::kClamp;

    /// Every parameter, declared once (core/parameters.hpp): key, help, unit, valid range. The
    /// value ranges need only be finite and ordered (Validate), so they declare no bounds.
    template <typename Self, typename Visit>
    static void Declare(Self& c, Visit&& visit) {
        visit(c.bins, {"bins", "b, number of buckets", "", 1, 1'000'000});
        visit(c.up_vector, {"up_vector", "height projection up vector: fixed (0,0,1) | pca", ""});
        visit(c.sensor_height_m, {"sensor_height_m", "added to heights so that 0 is the ground",
                                  "m", -1'000.0, 1'000.0});
        visit(c.height_min_m, {"height_min_m", "v_min of the height histogram", "m"});
        visit(c.height_max_m, {"height_max_m", "v_max of the height histogram", "m"});
        visit(c.range_min_m, {"range_min_m", "v_min of the range histogram", "m", 0.0});
        visit(c.range_max_m, {"range_max_m", "v_max of the range histogram", "m"});
        visit(c.out_of_range, {"out_of_range", "values outside [v_min, v_max]: clamp | drop", ""});
    }
    /// Throws ConfigError naming the first invalid field.
    void Validate() const;
    bool operator==(const HistogramConfig&) const = default;
};

/// A normalised histogram H_b (Röhling eq. 3–4) with the bookkeeping of how it was made.
struct Histogram {
    Projection projection = Projection::kHeight;
    double min_value = 0.0;                         ///< v_min, metres
    double max_value = 0.0;                         ///< v_max, metres
    std::vector<double> mass;                       ///< h_k, k = 0..b-1, non-negative, sums to 1
    Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< u used by the height projection
    std::size_t points_used = 0;                    ///< points counted in the buckets
    std::size_t points_skipped = 0;       ///< non-finite points (no return, corrupt values)
    std::size_t points_out_of_range = 0;  ///< finite points outside [v_min, v_max]
};

/// Builds the histogram of `cloud` under `projection` (Röhling eq. 1–4). Bucket k covers
/// [v_min + k*dI, v_min + (k+1)*dI), the last one also v_max. Non-finite points are skipped and
/// counted. Throws EmptyInputError when no point is left to count and ConfigError for an invalid
/// configuration. Thread-safe; O(|S| + b).
Histogram ComputeHistogram(PointsView cloud, Projection projection, const HistogramConfig& config);
/// The same for a PointCloud (or a braced list of points).
inline Histogram ComputeHistogram(const PointCloud& cloud, Projection projection,
                                  const HistogramConfig& config) {
    return ComputeHistogram(PointsView(cloud), projection, config);
}

}  // namespace lidarloop::core

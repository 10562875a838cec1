#include "lidarloop/core/histogram.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"

namespace lidarloop::core {
namespace {

void RequireFinite(double value, const char* field) {
    if (!std::isfinite(value)) {
        throw ConfigError(std::string("histogram.") + field + " must be a finite number");
    }
}

void RequireOrdered(double min_value, double max_value, const char* min_field,
                    const char* max_field) {
    if (!(min_value < max_value)) {
        throw ConfigError(std::string("histogram.") + min_field + " (" + std::to_string(min_value) +
                          ") must be smaller than histogram." + max_field + " (" +
                          std::to_string(max_value) + ")");
    }
    // The buckets divide the span: one that overflows would put every value in the first.
    if (!std::isfinite(max_value - min_value)) {
        throw ConfigError(std::string("histogram.") + max_field + " - " + min_field +
                          " must be a finite span, got " + NumberText(min_value) + " to " +
                          NumberText(max_value));
    }
}

// Points are counted in blocks, so that a projection can first compute a whole block's values
// with SIMD (ranges: four square roots at once).
constexpr std::size_t kBlockPoints = 256;

// The projection of a block of points, point by point: v(p) = z + offset or u . p + offset.
template <typename ValueOfPoint>
struct PointwiseValues {
    ValueOfPoint value_of;
    static constexpr bool kInRangeImpliesFinite = false;  // z says nothing about x and y
    void Prepare(const Eigen::Vector3f* /*points*/, std::size_t /*n*/) {}
    double operator()(std::size_t /*j*/, const Eigen::Vector3f& p) const { return value_of(p); }
};

inline float RangeOf(float x, float y, float z) { return std::sqrt((x * x + y * y) + z * z); }

// Ranges ||p|| of a block, four points per step where SSE2 is available. Both paths round the
// same way, so a point's range does not depend on its position in the block.
struct BlockRanges {
    float ranges[kBlockPoints];
    // A NaN or infinite coordinate makes the range NaN or infinite, never a value in range.
    static constexpr bool kInRangeImpliesFinite = true;

    void Prepare(const Eigen::Vector3f* points, std::size_t n) {
        std::size_t j = 0;
#if defined(__SSE2__)
        // Eigen::Vector3f is three packed floats: four points are twelve consecutive floats.
        static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
        const float* f = points->data();
        for (; j + 4 <= n; j += 4, f += 12) {
            const __m128 a = _mm_loadu_ps(f);      // x0 y0 z0 x1
            const __m128 b = _mm_loadu_ps(f + 4);  // y1 z1 x2 y2
            const __m128 c = _mm_loadu_ps(f + 8);  // z2 x3 y3 z3
            const __m128 x = _mm_shuffle_ps(_mm_shuffle_ps(a, a, _MM_SHUFFLE(0, 0, 3, 0)),
                                            _mm_shuffle_ps(b, c, _MM_SHUFFLE(1, 1, 2, 2)),
                                            _MM_SHUFFLE(2, 0, 1, 0));
            const __m128 y = _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 0, 1, 1)),
                                            _mm_shuffle_ps(b, c, _MM_SHUFFLE(2, 2, 3, 3)),
                                            _MM_SHUFFLE(2, 0, 2, 0));
            const __m128 z = _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 1, 2, 2)),
                                            _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 0, 0)),
                                            _MM_SHUFFLE(2, 0, 2, 0));
            const __m128 squared =
                _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)), _mm_mul_ps(z, z));
            _mm_storeu_ps(ranges + j, _mm_sqrt_ps(squared));
        }
#endif
        for (; j < n; ++j) ranges[j] = RangeOf(points[j].x(), points[j].y(), points[j].z());
    }
    double operator()(std::size_t j, const Eigen::Vector3f& /*p*/) const {
        return double{ranges[j]};
    }
};

// Counts the values of `cloud` into buckets; `values` gives the projection v(p) of point j of
// the block it prepared last.
template <typename BlockValues>
void CountValues(PointsView cloud, BlockValues values, const HistogramConfig& config,
                 std::vector<std::size_t>& counts, Histogram& histogram) {
    const double min_value = histogram.min_value;
    const double max_value = histogram.max_value;
    const auto bins = static_cast<long>(counts.size());
    const double buckets_per_unit = static_cast<double>(bins) / (max_value - min_value);
    const bool clamp = config.out_of_range == OutOfRangePolicy::kClamp;
    // Neighbouring points of a scan usually fall into the same bucket; counting them into
    // kWays interleaved copies of the histogram keeps the increments from waiting on each other.
    constexpr std::size_t kWays = 4;
    std::vector<std::uint32_t> partial(kWays * counts.size(), 0);
    std::size_t skipped = 0;
    std::size_t out_of_range = 0;
    for (std::size_t start = 0; start < cloud.size(); start += kBlockPoints) {
        const std::size_t n = std::min(kBlockPoints, cloud.size() - start);
        values.Prepare(cloud.data() + start, n);
        for (std::size_t j = 0; j < n; ++j) {
            const Eigen::Vector3f& p = cloud[start + j];
            const double v = values(j, p);  // garbage for a non-finite point, not used then
            const bool in_range = v >= min_value && v <= max_value;
            if (!(BlockValues::kInRangeImpliesFinite && in_range) && !p.allFinite()) {
                ++skipped;
                continue;
            }
            long k = 0;
            if (in_range) {
                // Truncation is floor here (the argument is >= 0) and, unlike std::floor without
                // SSE4.1, no library call; v == v_max lands in the last bucket (eq. 2's closed
                // end).
                k = std::min(static_cast<long>((v - min_value) * buckets_per_unit), bins - 1);
            } else {
                ++out_of_range;
                if (!clamp) continue;
                k = v < min_value ? 0 : bins - 1;
            }
            ++partial[(j % kWays) * counts.size() + static_cast<std::size_t>(k)];
        }
    }
    for (std::size_t way = 0; way < kWays; ++way) {
        for (std::size_t b = 0; b < counts.size(); ++b)
            counts[b] += partial[way * counts.size() + b];
    }
    histogram.points_skipped += skipped;
    histogram.points_out_of_range += out_of_range;
    histogram.points_used += cloud.size() - skipped - (clamp ? 0 : out_of_range);
}

template <typename ValueOfPoint>
PointwiseValues<ValueOfPoint> Pointwise(ValueOfPoint value_of) {
    return {value_of};
}

constexpr auto kOutOfRangePolicyNames = std::to_array<EnumName<OutOfRangePolicy>>({
    {OutOfRangePolicy::kClamp, "clamp"},
    {OutOfRangePolicy::kDrop, "drop"},
});
static_assert(IsOneToOne(kOutOfRangePolicyNames));

}  // namespace

std::string ToString(OutOfRangePolicy policy) {
    return std::string(NameOf(kOutOfRangePolicyNames, policy));
}

OutOfRangePolicy ParseOutOfRangePolicy(std::string_view name) {
    return ParseEnum(kOutOfRangePolicyNames, name, "out-of-range policy");
}

void HistogramConfig::Validate() const {
    // Finite first, so that a NaN is named as such rather than as outside a range.
    RequireFinite(sensor_height_m, "sensor_height_m");
    RequireFinite(height_min_m, "height_min_m");
    RequireFinite(height_max_m, "height_max_m");
    RequireFinite(range_min_m, "range_min_m");
    RequireFinite(range_max_m, "range_max_m");
    CheckDeclaredRanges(kSection, *this);
    RequireOrdered(height_min_m, height_max_m, "height_min_m", "height_max_m");
    RequireOrdered(range_min_m, range_max_m, "range_min_m", "range_max_m");
}

Histogram ComputeHistogram(PointsView cloud, Projection projection, const HistogramConfig& config) {
    config.Validate();
    if (cloud.empty()) throw EmptyInputError("the scan has no points");
    Histogram histogram;
    histogram.projection = projection;
    std::vector<std::size_t> counts(static_cast<std::size_t>(config.bins), 0);
    if (projection == Projection::kHeight) {
        histogram.min_value = config.height_min_m;
        histogram.max_value = config.height_max_m;
        if (config.up_vector == UpVectorMode::kPca) histogram.up = EstimateUpVectorPca(cloud);
        const Eigen::Vector3d up = histogram.up;
        const double offset_m = config.sensor_height_m;
        if (up == Eigen::Vector3d::UnitZ()) {  // the fixed up vector: the height is z
            CountValues(cloud, Pointwise([&](const Eigen::Vector3f& p) {
                            return double{p.z()} + offset_m;
                        }),
                        config, counts, histogram);
        } else {
            CountValues(cloud, Pointwise([&](const Eigen::Vector3f& p) {
                            return p.cast<double>().dot(up) + offset_m;
                        }),
                        config, counts, histogram);
        }
    } else {
        histogram.min_value = config.range_min_m;
        histogram.max_value = config.range_max_m;
        // Single-precision sqrt: the points are float already, and sqrt is the loop's cost.
        CountValues(cloud, BlockRanges{}, config, counts, histogram);
    }
    if (histogram.points_used == 0) {
        throw EmptyInputError("no point of the scan is usable (" +
                              std::to_string(histogram.points_skipped) + " non-finite, " +
                              std::to_string(histogram.points_out_of_range) +
                              " outside the value range and dropped)");
    }
    // Röhling eq. (4); with kDrop, |S| is the number of points kept so that sum_k h_k = 1.
    histogram.mass.resize(counts.size());
    const double inverse_total = 1.0 / static_cast<double>(histogram.points_used);
    for (std::size_t k = 0; k < counts.size(); ++k) {
        histogram.mass[k] = static_cast<double>(counts[k]) * inverse_total;
    }
    return histogram;
}

}  // namespace lidarloop::core

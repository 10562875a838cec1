#include "lidarloop/sim/route.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/sim/detail/random.hpp"

namespace lidarloop::sim {
namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
}

double WrapAngle(double angle) { return std::remainder(angle, 2.0 * std::numbers::pi); }

std::string NodeText(const Eigen::Vector2i& node) {
    return "(" + std::to_string(node.x()) + ", " + std::to_string(node.y()) + ")";
}

void CheckLegs(const std::vector<RouteLeg>& legs) {
    if (legs.empty()) throw core::ConfigError("a route needs at least one leg");
    for (std::size_t k = 0; k < legs.size(); ++k) {
        const RouteLeg& leg = legs[k];
        const RouteLeg& next = legs[(k + 1) % legs.size()];
        const std::string name = "route leg " + std::to_string(k);
        if ((leg.to - leg.from).cwiseAbs().sum() != 1) {
            throw core::ConfigError(name + " from " + NodeText(leg.from) + " to " +
                                    NodeText(leg.to) + " does not join adjacent nodes");
        }
        if (leg.lane != 0 && leg.lane != 1) {
            throw core::ConfigError(name + " has lane " + std::to_string(leg.lane) +
                                    ", expected 0 or 1");
        }
        if (leg.to != next.from) {
            throw core::ConfigError(name + " ends at " + NodeText(leg.to) +
                                    " but the next leg starts at " + NodeText(next.from) +
                                    (k + 1 == legs.size() ? " (the lap must be closed)" : ""));
        }
    }
}

struct LaneLine {
    Eigen::Vector2d a;  // start, in the lane
    Eigen::Vector2d b;  // end, in the lane
    Eigen::Vector2d u;  // unit direction
};

LaneLine LineOf(const RouteLeg& leg, const SceneLayout& layout) {
    const Eigen::Vector2d from = leg.from.cast<double>() * layout.block_pitch_m;
    const Eigen::Vector2d to = leg.to.cast<double>() * layout.block_pitch_m;
    const Eigen::Vector2d u = (to - from).normalized();
    const Eigen::Vector2d right(u.y(), -u.x());
    const double offset = (leg.lane + 0.5) * layout.lane_width_m;
    return {from + offset * right, to + offset * right, u};
}

// The closed polyline of the lanes: a point near the start of leg 0, then at every node the corner
// of the two lane lines (a turn) or the end of one and the start of the next (straight on or
// U-turn).
std::vector<Eigen::Vector2d> LanePolygon(const std::vector<RouteLeg>& legs,
                                         const SceneLayout& layout) {
    std::vector<LaneLine> lines;
    for (const auto& leg : legs) lines.push_back(LineOf(leg, layout));
    // Start on the first leg just past the rounding of its first node (4 sigma), so that a
    // sequence starts driving away from home rather than in a turn.
    const double start = std::min(0.5 * layout.block_pitch_m, 4.0 * layout.path_smoothing_m);
    std::vector<Eigen::Vector2d> polygon = {lines[0].a + start * lines[0].u};
    for (std::size_t k = 0; k < lines.size(); ++k) {
        const LaneLine& cur = lines[k];
        const LaneLine& next = lines[(k + 1) % lines.size()];
        const double turn = Cross(cur.u, next.u);
        if (std::abs(turn) > 0.5) {
            const double s = Cross(next.a - cur.a, next.u) / turn;
            polygon.push_back(cur.a + s * cur.u);
        } else {
            polygon.push_back(cur.b);
            if ((next.a - cur.b).norm() > 1e-9) polygon.push_back(next.a);
        }
    }
    return polygon;
}

// Samples of the closed polygon at (nearly) `step` spacing, evenly over its length.
std::vector<Eigen::Vector2d> Resample(const std::vector<Eigen::Vector2d>& polygon, double step) {
    double total = 0.0;
    for (std::size_t k = 0; k < polygon.size(); ++k) {
        total += (polygon[(k + 1) % polygon.size()] - polygon[k]).norm();
    }
    const auto count = static_cast<std::size_t>(std::ceil(total / step));
    const double even_step = total / static_cast<double>(count);
    std::vector<Eigen::Vector2d> samples;
    samples.reserve(count);
    std::size_t k = 0;
    double segment_start = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
        const double s = static_cast<double>(i) * even_step;
        Eigen::Vector2d a = polygon[k];
        Eigen::Vector2d b = polygon[(k + 1) % polygon.size()];
        while (segment_start + (b - a).norm() < s && k + 1 < polygon.size()) {
            segment_start += (b - a).norm();
            ++k;
            a = polygon[k];
            b = polygon[(k + 1) % polygon.size()];
        }
        const double length = (b - a).norm();
        const double f = length > 0.0 ? std::clamp((s - segment_start) / length, 0.0, 1.0) : 0.0;
        samples.push_back(a + f * (b - a));
    }
    return samples;
}

// Circular Gaussian smoothing over the sample index (samples are evenly spaced). Plain arrays:
// this runs over tens of thousands of samples, also in unoptimised test builds.
std::vector<Eigen::Vector2d> Smooth(const std::vector<Eigen::Vector2d>& samples,
                                    double sigma_samples) {
    const int radius = static_cast<int>(std::ceil(3.0 * sigma_samples));
    std::vector<double> weights;
    double sum = 0.0;
    for (int j = -radius; j <= radius; ++j) {
        weights.push_back(std::exp(-0.5 * (j / sigma_samples) * (j / sigma_samples)));
        sum += weights.back();
    }
    for (double& w : weights) w /= sum;
    const auto n = static_cast<long>(samples.size());
    std::vector<double> x(samples.size());
    std::vector<double> y(samples.size());
    for (long i = 0; i < n; ++i) {
        x[i] = samples[i].x();
        y[i] = samples[i].y();
    }
    std::vector<Eigen::Vector2d> smooth(samples.size());
    for (long i = 0; i < n; ++i) {
        double sx = 0.0;
        double sy = 0.0;
        for (int j = -radius; j <= radius; ++j) {
            const long k = ((i + j) % n + n) % n;
            sx += weights[j + radius] * x[k];
            sy += weights[j + radius] * y[k];
        }
        smooth[i] = {sx, sy};
    }
    return smooth;
}

constexpr auto kRouteTypeNames = std::to_array<core::EnumName<RouteType>>({
    {RouteType::kUTurn, "uturn"},
    {RouteType::kFigureEight, "figure8"},
    {RouteType::kGrid, "grid"},
});
static_assert(core::IsOneToOne(kRouteTypeNames));

}  // namespace

std::string ToString(RouteType type) { return std::string(core::NameOf(kRouteTypeNames, type)); }

RouteType ParseRouteType(std::string_view name) {
    return core::ParseEnum(kRouteTypeNames, name, "route");
}

void RouteConfig::Validate() const {
    if (!(spacing_min_m > 0.0 && spacing_min_m <= 50.0)) {
        throw core::ConfigError("route.spacing_min_m must be in (0, 50], got " +
                                core::NumberText(spacing_min_m));
    }
    if (!(spacing_max_m >= spacing_min_m && spacing_max_m <= 50.0)) {
        throw core::ConfigError("route.spacing_max_m must be in [spacing_min_m, 50], got " +
                                core::NumberText(spacing_max_m));
    }
    if (uturn_blocks < 0 || uturn_blocks > 100) {
        throw core::ConfigError("route.uturn_blocks must be in [0, 100], got " +
                                std::to_string(uturn_blocks));
    }
}

std::vector<RouteLeg> RouteLegs(RouteType type, int uturn_blocks) {
    using V = Eigen::Vector2i;
    std::vector<RouteLeg> legs;
    const auto path = [&legs](std::initializer_list<V> nodes, int lane) {
        for (auto it = nodes.begin(); it + 1 != nodes.end(); ++it) {
            legs.push_back({*it, *(it + 1), lane});
        }
    };
    switch (type) {
        case RouteType::kUTurn: {
            const int k = std::max(1, uturn_blocks);
            for (int lane = 0; lane < 2; ++lane) {
                for (int i = 0; i < k; ++i) legs.push_back({{i, 0}, {i + 1, 0}, lane});
                for (int i = k; i > 0; --i) legs.push_back({{i, 0}, {i - 1, 0}, lane});
            }
            break;
        }
        case RouteType::kFigureEight:
            for (int lane = 0; lane < 2; ++lane) {
                path({{1, 1}, {2, 1}, {2, 2}, {1, 2}, {1, 1}, {1, 0}, {0, 0}, {0, 1}, {1, 1}},
                     lane);
            }
            break;
        case RouteType::kGrid:
            path({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {1, 1}, {0, 1}, {0, 0}}, 0);
            path({{0, 0}, {1, 0}}, 1);                          // again, a lane to the side
            path({{1, 0}, {1, 1}, {2, 1}, {2, 0}, {1, 0}}, 0);  // three streets in reverse
            path({{1, 0}, {1, 1}}, 1);          // the middle street again, a lane to the side
            path({{1, 1}, {0, 1}, {0, 0}}, 0);  // exactly again
            break;
    }
    return legs;
}

RoutePath::RoutePath(std::vector<RouteLeg> legs, const SceneLayout& layout)
    : legs_(std::move(legs)) {
    CheckLegs(legs_);
    const double sigma = layout.path_smoothing_m;
    const double samples_per_sigma = 10.0;
    const std::vector<Eigen::Vector2d> smooth =
        Smooth(Resample(LanePolygon(legs_, layout), sigma / samples_per_sigma), samples_per_sigma);
    const std::size_t n = smooth.size();
    points_m_ = smooth;
    points_m_.push_back(smooth.front());
    arc_m_.assign(n + 1, 0.0);
    heading_rad_.assign(n + 1, 0.0);
    for (std::size_t i = 0; i <= n; ++i) {
        if (i > 0) arc_m_[i] = arc_m_[i - 1] + (points_m_[i] - points_m_[i - 1]).norm();
        const Eigen::Vector2d d = smooth[(i + 1) % n] - smooth[(i + n - 1) % n];
        const double heading = std::atan2(d.y(), d.x());
        heading_rad_[i] =
            i == 0 ? heading : heading_rad_[i - 1] + WrapAngle(heading - heading_rad_[i - 1]);
    }
}

RoutePoint RoutePath::At(double s_m) const {
    const double lap = lap_length_m();
    double s = std::fmod(s_m, lap);
    if (s < 0.0) s += lap;
    const auto upper = std::upper_bound(arc_m_.begin(), arc_m_.end(), s);
    const auto i = static_cast<std::size_t>(
        std::clamp<long>(upper - arc_m_.begin() - 1, 0, static_cast<long>(arc_m_.size()) - 2));
    const double length = arc_m_[i + 1] - arc_m_[i];
    const double f = length > 0.0 ? std::clamp((s - arc_m_[i]) / length, 0.0, 1.0) : 0.0;
    return {points_m_[i] + f * (points_m_[i + 1] - points_m_[i]),
            WrapAngle(heading_rad_[i] + f * (heading_rad_[i + 1] - heading_rad_[i]))};
}

NodeRange RoutePath::VisitedNodes() const {
    NodeRange range{legs_[0].from.x(), legs_[0].from.x(), legs_[0].from.y(), legs_[0].from.y()};
    for (const auto& leg : legs_) {
        for (const Eigen::Vector2i& node : {leg.from, leg.to}) {
            range.i_min = std::min(range.i_min, node.x());
            range.i_max = std::max(range.i_max, node.x());
            range.j_min = std::min(range.j_min, node.y());
            range.j_max = std::max(range.j_max, node.y());
        }
    }
    return range;
}

SpacingProfile::SpacingProfile(double spacing_min_m, double spacing_max_m, std::uint64_t seed)
    : mean_m_(0.5 * (spacing_min_m + spacing_max_m)) {
    detail::Random rng(detail::StreamSeed(seed, detail::Stream::kSpacing));
    const double half_range = 0.5 * (spacing_max_m - spacing_min_m);
    const double periods[2] = {rng.Uniform(40.0, 80.0), rng.Uniform(150.0, 300.0)};
    const double shares[2] = {0.6, 0.4};
    for (int k = 0; k < 2; ++k) {
        frequency_[k] = 2.0 * std::numbers::pi / periods[k];
        // The step's deviation from the mean is at most amplitude * frequency (|sin x| <= |x|).
        amplitude_m_[k] = shares[k] * half_range / frequency_[k];
        phase_[k] = rng.Uniform(0.0, 2.0 * std::numbers::pi);
    }
}

double SpacingProfile::ArcLength(std::size_t index) const {
    const double i = static_cast<double>(index);
    double s = mean_m_ * i;
    for (int k = 0; k < 2; ++k) {
        s += amplitude_m_[k] * (std::sin(frequency_[k] * i + phase_[k]) - std::sin(phase_[k]));
    }
    return s;
}

}  // namespace lidarloop::sim

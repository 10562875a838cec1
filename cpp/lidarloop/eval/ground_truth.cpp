#include "lidarloop/eval/ground_truth.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/kd_tree.hpp"

namespace lidarloop::eval {
namespace {

std::string Format(double value) {
    std::ostringstream out;
    out << value;
    return out.str();
}

// The sensor's forward axis projected on the world ground plane (not normalised).
Eigen::Vector2d GroundHeading(const core::Transform& T_world_sensor) {
    return T_world_sensor.linear().col(0).head<2>();
}

// Below this length (of a unit axis' projection) the sensor points within ~1e-6 rad of the
// vertical and its projected heading is rounding noise.
constexpr double kMinHeadingLength = 1e-6;

// Angle between two ground-plane vectors in degrees; atan2 keeps full precision near 0° and
// 180°.
double AngleDeg(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    if (a.norm() < kMinHeadingLength || b.norm() < kMinHeadingLength) return 0.0;
    const double cross = a.x() * b.y() - a.y() * b.x();
    return std::atan2(std::abs(cross), a.dot(b)) * (180.0 / std::numbers::pi);
}

void CheckPoses(const std::vector<core::StampedPose>& poses) {
    for (std::size_t i = 0; i < poses.size(); ++i) {
        if (!std::isfinite(poses[i].time_s) || !poses[i].T_world_sensor.matrix().allFinite()) {
            throw core::Error("ground truth: pose " + std::to_string(i) +
                              " has a non-finite time or transform");
        }
    }
}

// Partners per scan in CSR form; `loops` is sorted by (i, j), so every list comes out sorted.
void FillPartners(GroundTruth& truth) {
    const std::size_t n = truth.size();
    truth.partner_offsets.assign(n + 1, 0);
    for (const auto& loop : truth.loops) {
        ++truth.partner_offsets[loop.i + 1];
        ++truth.partner_offsets[loop.j + 1];
    }
    for (std::size_t k = 0; k < n; ++k) truth.partner_offsets[k + 1] += truth.partner_offsets[k];
    truth.partners.assign(truth.partner_offsets[n], 0);
    std::vector<std::size_t> next(truth.partner_offsets.begin(), truth.partner_offsets.end() - 1);
    for (const auto& loop : truth.loops) {
        truth.partners[next[loop.i]++] = loop.j;
        truth.partners[next[loop.j]++] = loop.i;
    }
}

}  // namespace

void GroundTruthConfig::Validate() const {
    if (!std::isfinite(distance_m) || distance_m <= 0.0) {
        throw core::ConfigError("ground_truth.distance_m must be a finite number > 0, got " +
                                Format(distance_m));
    }
    if (!std::isfinite(max_heading_deg) || max_heading_deg < 0.0 || max_heading_deg > 180.0) {
        throw core::ConfigError(
            "ground_truth.max_heading_deg must be in [0, 180] (0 = no heading rule), got " +
            Format(max_heading_deg));
    }
    min_gap.Validate("ground_truth.min_gap");
}

std::string GroundTruthConfig::Describe() const {
    std::string text = "two scans show the same place when their sensor positions are less than " +
                       Format(distance_m) + " m apart (3-D Euclidean)";
    if (max_heading_deg > 0.0) {
        text +=
            " and their headings (forward axes projected on the ground plane) differ by less "
            "than " +
            Format(max_heading_deg) + " deg";
    }
    const bool scans = min_gap.unit == core::MinGap::Unit::kScans;
    if (scans && min_gap.value == 0.0) {
        text += "; every pair of distinct scans is evaluated";
    } else {
        text += "; only pairs more than " + Format(min_gap.value) + (scans ? " scans" : " s") +
                " apart in the sequence are evaluated";
    }
    return text;
}

double HeadingDifferenceDeg(const core::Transform& T_world_a, const core::Transform& T_world_b) {
    return AngleDeg(GroundHeading(T_world_a), GroundHeading(T_world_b));
}

bool GroundTruth::IsLoop(std::size_t i, std::size_t j) const {
    const auto first = partners.begin() + static_cast<std::ptrdiff_t>(partner_offsets[i]);
    const auto last = partners.begin() + static_cast<std::ptrdiff_t>(partner_offsets[i + 1]);
    return std::binary_search(first, last, j);
}

std::size_t GroundTruth::OverlappingCount() const {
    std::size_t count = 0;
    for (std::size_t i = 0; i < size(); ++i) count += Overlapping(i) ? 1 : 0;
    return count;
}

std::size_t GroundTruth::ComparablePairCount() const {
    const std::size_t n = size();
    if (config.min_gap.unit == core::MinGap::Unit::kScans) {
        // |i - j| > S  <=>  |i - j| >= floor(S) + 1.
        const double first_apart = std::floor(config.min_gap.value) + 1.0;
        if (first_apart >= static_cast<double>(n)) return 0;
        const std::size_t m = n - static_cast<std::size_t>(first_apart);
        return m * (m + 1) / 2;
    }
    // |t_i - t_j| > value, counted on sorted times: all pairs minus those within the gap. The
    // test is MinGap::Allows' own expression (t_j - t_k, monotone in t_j), so no rounding differs.
    std::vector<double> sorted = times_s;
    std::sort(sorted.begin(), sorted.end());
    std::size_t within = 0;
    for (std::size_t k = 0; k < n; ++k) {
        const auto end =
            std::partition_point(sorted.begin() + static_cast<std::ptrdiff_t>(k) + 1, sorted.end(),
                                 [&](double t) { return !(t - sorted[k] > config.min_gap.value); });
        within += static_cast<std::size_t>(end - sorted.begin()) - k - 1;
    }
    return n * (n - 1) / 2 - within;
}

std::string GroundTruth::Describe() const {
    return config.Describe() + " (" + std::to_string(size()) + " scans, " +
           std::to_string(loops.size()) + " positive pairs, " + std::to_string(OverlappingCount()) +
           " overlapping scans)";
}

GroundTruth BuildGroundTruth(const std::vector<core::StampedPose>& poses,
                             const GroundTruthConfig& config) {
    config.Validate();
    CheckPoses(poses);
    const std::size_t n = poses.size();
    GroundTruth truth;
    truth.config = config;
    truth.times_s.resize(n);
    std::vector<Eigen::Vector3d> positions(n);
    std::vector<Eigen::Vector2d> headings(n);
    for (std::size_t i = 0; i < n; ++i) {
        truth.times_s[i] = poses[i].time_s;
        positions[i] = poses[i].T_world_sensor.translation();
        headings[i] = GroundHeading(poses[i].T_world_sensor);
    }
    const bool use_heading = config.max_heading_deg > 0.0;
    const auto same_place_rules = [&](std::size_t i, std::size_t j) {
        return truth.Comparable(i, j) &&
               (!use_heading || AngleDeg(headings[i], headings[j]) < config.max_heading_deg);
    };
    const core::KdTree3 tree(positions);
    for (std::size_t i = 0; i < n; ++i) {
        for (const std::size_t j : tree.RadiusSearch(positions[i], config.distance_m)) {
            if (j > i && same_place_rules(i, j)) {
                truth.loops.push_back({i, j, (positions[i] - positions[j]).norm()});
            }
        }
    }
    FillPartners(truth);
    truth.nearest.assign(n, kNoScan);
    truth.nearest_distance_m.assign(n, std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < n; ++i) {
        const auto found =
            tree.NearestIf(positions[i], [&](std::size_t j) { return same_place_rules(i, j); });
        if (found) {
            truth.nearest[i] = found->index;
            truth.nearest_distance_m[i] = found->distance_m;
        }
    }
    return truth;
}

}  // namespace lidarloop::eval

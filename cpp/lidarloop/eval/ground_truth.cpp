#include "lidarloop/eval/ground_truth.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <utility>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/kd_tree.hpp"

namespace lidarloop::eval {
namespace {

std::string Format(double value) {
    std::ostringstream out;
    out << value;
    return out.str();
}

const char* UnitSymbol(core::MinGap::Unit unit) {
    switch (unit) {
        case core::MinGap::Unit::kScans:
            return "scans";
        case core::MinGap::Unit::kSeconds:
            return "s";
        case core::MinGap::Unit::kMetres:
            return "m of path";
    }
    return "";
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
            throw core::ConfigError("ground truth: pose " + std::to_string(i) +
                                    " has a non-finite time or transform");
        }
    }
}

// Per scan its first partner, and the number of pairs: one radius search a scan, whose sorted
// answer puts the first partner first.
void FillPartners(GroundTruth& truth) {
    truth.first_partner.assign(truth.size(), kNoScan);
    for (std::size_t i = 0; i < truth.size(); ++i) {
        for (const std::size_t j :
             truth.tree->RadiusSearch(truth.positions_m[i], truth.config.distance_m)) {
            if (!truth.IsLoop(i, j)) continue;
            if (truth.first_partner[i] == kNoScan) truth.first_partner[i] = j;
            truth.loop_count += j > i ? 1 : 0;
        }
    }
}

void FillNearest(GroundTruth& truth) {
    const std::size_t n = truth.size();
    truth.nearest.assign(n, kNoScan);
    truth.nearest_distance_m.assign(n, std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < n; ++i) {
        const auto found = truth.tree->NearestIf(
            truth.positions_m[i], [&](std::size_t j) { return truth.SamePlaceRules(i, j); });
        if (found) {
            truth.nearest[i] = found->index;
            truth.nearest_distance_m[i] = found->distance_m;
        }
    }
}

// Comparable pairs under a path rule. The path grows with the index, and so do the scan gap and
// (when the times are sorted) the time gap: Comparable(k, j) for j > k then holds from some j on,
// found by bisection with Comparable itself. Unsorted times: every pair, O(n^2).
std::size_t ComparablePairsAlongPath(const GroundTruth& truth) {
    const std::size_t n = truth.size();
    const bool monotone = truth.config.min_gap.unit != core::MinGap::Unit::kSeconds ||
                          std::is_sorted(truth.times_s.begin(), truth.times_s.end());
    std::size_t count = 0;
    for (std::size_t k = 0; k < n; ++k) {
        if (!monotone) {
            for (std::size_t j = k + 1; j < n; ++j) count += truth.Comparable(k, j) ? 1 : 0;
            continue;
        }
        std::size_t lo = k + 1, hi = n;  // the first comparable j lies in [lo, hi]
        while (lo < hi) {
            const std::size_t mid = lo + (hi - lo) / 2;
            if (truth.Comparable(k, mid)) {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        count += n - lo;
    }
    return count;
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
    if (!std::isfinite(min_path_m) || min_path_m < 0.0) {
        throw core::ConfigError("ground_truth.min_path_m must be a finite number >= 0, got " +
                                Format(min_path_m));
    }
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
    if (scans && min_gap.value == 0.0 && min_path_m == 0.0) {
        text += "; every pair of distinct scans is evaluated";
        return text;
    }
    text += "; only pairs more than " + Format(min_gap.value) + " " + UnitSymbol(min_gap.unit) +
            " apart in the sequence";
    if (min_path_m > 0.0) text += " and more than " + Format(min_path_m) + " m of path apart";
    return text + " are evaluated";
}

double HeadingDifferenceDeg(const core::Transform& T_world_a, const core::Transform& T_world_b) {
    return AngleDeg(GroundHeading(T_world_a), GroundHeading(T_world_b));
}

bool GroundTruth::SamePlaceRules(std::size_t i, std::size_t j) const {
    return Comparable(i, j) &&
           (ground_headings.empty() ||
            AngleDeg(ground_headings[i], ground_headings[j]) < config.max_heading_deg);
}

bool GroundTruth::IsLoop(std::size_t i, std::size_t j) const {
    if (i > j) std::swap(i, j);
    // KdTree3::RadiusSearch's predicate, with the query i and the found point j, as in
    // ForEachLoop: the same doubles decide, so both agree even exactly at the boundary.
    return (positions_m[j] - positions_m[i]).squaredNorm() <
               config.distance_m * config.distance_m &&
           SamePlaceRules(i, j);
}

void GroundTruth::ForEachLoop(const std::function<void(const LoopPair&)>& each) const {
    for (std::size_t i = 0; i < size(); ++i) {
        for (const std::size_t j : tree->RadiusSearch(positions_m[i], config.distance_m)) {
            if (j > i && SamePlaceRules(i, j))
                each({i, j, (positions_m[i] - positions_m[j]).norm()});
        }
    }
}

std::vector<LoopPair> GroundTruth::Loops() const {
    std::vector<LoopPair> loops;
    loops.reserve(loop_count);
    ForEachLoop([&](const LoopPair& loop) { loops.push_back(loop); });
    return loops;
}

std::size_t GroundTruth::OverlappingCount() const {
    std::size_t count = 0;
    for (std::size_t i = 0; i < size(); ++i) count += Overlapping(i) ? 1 : 0;
    return count;
}

std::size_t GroundTruth::ComparablePairCount() const {
    const std::size_t n = size();
    if (config.min_path_m > 0.0 || config.min_gap.unit == core::MinGap::Unit::kMetres)
        return ComparablePairsAlongPath(*this);
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
           std::to_string(loop_count) + " positive pairs, " + std::to_string(OverlappingCount()) +
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
    truth.positions_m.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        truth.times_s[i] = poses[i].time_s;
        truth.positions_m[i] = poses[i].T_world_sensor.translation();
    }
    if (config.max_heading_deg > 0.0) {
        for (const auto& pose : poses)
            truth.ground_headings.push_back(GroundHeading(pose.T_world_sensor));
    }
    truth.path_m = core::CumulativePathM(poses);
    truth.tree = std::make_shared<const core::KdTree3>(truth.positions_m);
    FillPartners(truth);
    FillNearest(truth);
    return truth;
}

}  // namespace lidarloop::eval

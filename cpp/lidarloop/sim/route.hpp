#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/sim/scene.hpp"

namespace lidarloop::sim {

/// Routes through the street grid of a scene. Each is one closed lap, driven again and again
/// until the sequence has its scans; every lap revisits places by construction.
enum class RouteType {
    kUTurn,  ///< Röhling's route A: out along one street, U-turn, home on the opposite lane
             ///< (the same road in the opposite direction, one lane width to the side), U-turn;
             ///< then the same in the outer lanes (same direction, one lane width offset)
    kFigureEight,  ///< around one block counter-clockwise and the diagonal one clockwise,
                   ///< crossing at the shared corner; a lap in the inner lanes, one in the outer
    kGrid,  ///< exploration of a 2 x 1 block grid: every street driven twice, four of them in
            ///< the opposite direction, two in the same direction a lane to the side, two
            ///< exactly again, and crossings at the middle nodes
};

std::string ToString(RouteType type);
/// Parses "uturn" / "figure8" / "grid"; throws core::ConfigError listing the names.
RouteType ParseRouteType(std::string_view name);

/// How the vehicle drives.
struct RouteConfig {
    RouteType type = RouteType::kUTurn;
    double spacing_min_m = 1.0;  ///< smallest distance between consecutive scans, (0, 50]
    double spacing_max_m = 2.0;  ///< largest distance between consecutive scans, >= spacing_min_m
    /// Street length of kUTurn in blocks, [0, 100]; 0 chooses it from the sequence: as many
    /// blocks as one out-and-back of the scans covers, 1 to 12.
    int uturn_blocks = 0;

    /// Throws core::ConfigError naming the first invalid field ("route.spacing_min_m ...").
    void Validate() const;
};

/// One leg of a route between adjacent street nodes, driven on the right side of the street in
/// lane `lane` (0: next to the centre line, 1: the outer lane).
struct RouteLeg {
    Eigen::Vector2i from = Eigen::Vector2i::Zero();
    Eigen::Vector2i to = Eigen::Vector2i::Zero();
    int lane = 0;
};

/// The legs of one lap, starting and ending at the same node. `uturn_blocks` (>= 1) is the
/// length in blocks of the street that kUTurn goes out along; the other routes ignore it.
std::vector<RouteLeg> RouteLegs(RouteType type, int uturn_blocks = 4);

/// A position on a route: where the vehicle is and where it heads (world frame).
struct RoutePoint {
    Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
    double heading_rad = 0.0;  ///< direction of travel, counter-clockwise from the world x axis
};

/// The smooth closed path of a lap. Each leg is a straight line in its lane; corners, lane changes
/// and U-turns are rounded by a Gaussian of sigma path_smoothing_m over the arc length of that
/// polyline (which cuts a right-angled corner by about 0.56 sigma towards its inside, well within
/// the intersection). Arc length 0 is on the first leg, 4 sigma (at most half a block) past its
/// first node. Immutable, thread-safe.
class RoutePath {
public:
    /// Throws core::ConfigError when a leg does not join adjacent nodes, legs do not follow on
    /// from each other, the lap is not closed, or a lane is not 0 or 1.
    RoutePath(std::vector<RouteLeg> legs, const SceneLayout& layout);

    double lap_length_m() const { return arc_m_.back(); }
    /// The point at arc length `s_m` >= 0, wrapping around after each lap.
    RoutePoint At(double s_m) const;
    /// The smallest node range that holds every node of the lap.
    NodeRange VisitedNodes() const;
    const std::vector<RouteLeg>& legs() const { return legs_; }

private:
    std::vector<RouteLeg> legs_;
    std::vector<Eigen::Vector2d> points_m_;  // samples of the smoothed lap; last == first
    std::vector<double> arc_m_;              // arc length at each sample
    std::vector<double> heading_rad_;        // unwrapped heading at each sample
};

/// How far the vehicle moves between scans: a smooth, seeded variation within
/// [spacing_min_m, spacing_max_m] (two sinusoids over the scan index, periods of 40-80 and
/// 150-300 scans), i.e. varying speed at a fixed scan rate.
class SpacingProfile {
public:
    SpacingProfile(double spacing_min_m, double spacing_max_m, std::uint64_t seed);
    /// Distance travelled from scan 0 to scan `index`, metres; strictly increasing in index.
    double ArcLength(std::size_t index) const;

private:
    double mean_m_ = 1.5;
    double amplitude_m_[2] = {0.0, 0.0};
    double frequency_[2] = {0.0, 0.0};  // radians per scan
    double phase_[2] = {0.0, 0.0};
};

}  // namespace lidarloop::sim

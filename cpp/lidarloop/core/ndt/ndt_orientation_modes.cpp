#include "lidarloop/core/ndt/ndt_orientation_modes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>

#include <Eigen/Eigenvalues>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

// The lines are grouped into bins of an equal-area map of the upper half sphere (Lambert's
// azimuthal projection onto a disc of radius sqrt 2, cut by a square grid), and mean shift walks
// over bins: a few hundred instead of tens of thousands of cells. A bin that lies wholly inside
// or outside a window (by its angular radius and the triangle inequality of the angle between
// lines) is taken or left as a whole with its exact scatter; only the lines of bins on the rim
// are tested one by one. So which lines a window holds does not depend on the bins, and a mode
// is a function of the lines alone. 32 x 32 squares are at most ~7 degrees wide.
constexpr int kGrid = 32;
constexpr double kDiscRadius = std::numbers::sqrt2;
// Mean shift with a flat window stops once the set of lines inside stops changing; the direction
// is then its own principal axis again. A set that alternates between two states is cut off.
constexpr int kMaxIterations = 50;
constexpr double kConverged = 1e-12;  // 1 - |cos| between two steps
// Seeds are taken in decreasing order of the lines they hold, so the cap only drops the weakest:
// scattered noise far from every surface.
constexpr std::size_t kMaxSeeds = 64;
// A direction held by fewer lines than this share of all is a few stray cells, whose orientation
// differs between two scans of one place; as a peak it would only multiply the rotation
// candidates (eq. 7 measures Y against its own strongest member, however weak). A wall seen from
// afar holds more.
constexpr double kMinPeakShare = 0.01;
// A peak gathers its lines near its centre: an even spread puts a quarter of a window's lines
// within half its angle, a surface's normals nearly all. A mode with less than half there is a
// shoulder: scattered lines whose window reaches into the flank of a surface beside it.
constexpr double kMinCoreShare = 0.5;

// The lines of one bin: lines[first, last) of the sorted lines, their scatter sum of v v^T, their
// mean direction, and the largest angle between it and any of them.
struct Bin {
    std::size_t first = 0;
    std::size_t last = 0;
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
    double radius_rad = 0.0;

    double count() const { return static_cast<double>(last - first); }
};

// Unit lines turned into the upper half space, grouped by bin, and the occupied bins.
struct BinnedLines {
    std::vector<Eigen::Vector3d> lines;
    std::vector<Bin> bins;
    std::vector<double> x, y, z;  // the bins' directions as columns, for the window test
};

int BinIndex(const Eigen::Vector3d& upper) {
    const double scale = std::sqrt(2.0 / (1.0 + upper.z()));  // Lambert: equal areas
    const auto cell = [](double coordinate) {
        const double unit = (coordinate + kDiscRadius) / (2.0 * kDiscRadius);
        return std::clamp(static_cast<int>(unit * kGrid), 0, kGrid - 1);
    };
    return cell(upper.y() * scale) * kGrid + cell(upper.x() * scale);
}

// Sums of one bin of the grid while the lines are read: count, sum of the (upper) unit vectors
// and the six distinct entries of their scatter.
struct BinSums {
    std::size_t count = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double xx = 0.0, xy = 0.0, xz = 0.0, yy = 0.0, yz = 0.0, zz = 0.0;

    void Add(const Eigen::Vector3d& v) {
        ++count;
        sum += v;
        xx += v.x() * v.x(), xy += v.x() * v.y(), xz += v.x() * v.z();
        yy += v.y() * v.y(), yz += v.y() * v.z(), zz += v.z() * v.z();
    }
    Eigen::Matrix3d Scatter() const {
        Eigen::Matrix3d scatter;
        scatter << xx, xy, xz, xy, yy, yz, xz, yz, zz;
        return scatter;
    }
};

// Pass 1: every usable line, turned into the upper half space, and its bin, with the bins' sums.
struct ReadLines {
    std::vector<Eigen::Vector3d> unit;
    std::vector<std::uint16_t> bin;
    std::vector<BinSums> sums = std::vector<BinSums>(kGrid * kGrid);
};

ReadLines ReadAndBin(std::span<const float> x, std::span<const float> y, std::span<const float> z) {
    ReadLines read;
    read.unit.reserve(x.size());
    read.bin.reserve(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        Eigen::Vector3d v(x[i], y[i], z[i]);
        const double norm = v.norm();
        if (!std::isfinite(norm) || norm <= 0.0) continue;  // no line
        v /= norm;
        if (v.z() < 0.0) v = -v;
        const int b = BinIndex(v);
        read.unit.push_back(v);
        read.bin.push_back(static_cast<std::uint16_t>(b));
        read.sums[static_cast<std::size_t>(b)].Add(v);
    }
    return read;
}

// Pass 2: the lines sorted by bin (counting sort), and the occupied bins with their directions
// and radii.
BinnedLines BinLines(std::span<const float> x, std::span<const float> y, std::span<const float> z) {
    const ReadLines read = ReadAndBin(x, y, z);
    std::vector<std::size_t> slot(read.sums.size(), 0);  // first index of each grid bin
    std::vector<int> occupied(read.sums.size(), -1);     // its index in `bins`
    BinnedLines out;
    std::size_t first = 0;
    for (std::size_t b = 0; b < read.sums.size(); ++b) {
        slot[b] = first;
        const BinSums& sums = read.sums[b];
        if (sums.count == 0) continue;
        occupied[b] = static_cast<int>(out.bins.size());
        Bin bin;
        bin.first = first;
        bin.last = first + sums.count;
        bin.scatter = sums.Scatter();
        bin.direction = sums.sum.normalized();  // lines of one bin are a few degrees apart
        bin.radius_rad = 1.0;                   // holds the smallest |cos| until the end
        out.bins.push_back(bin);
        first = bin.last;
    }
    out.lines.resize(read.unit.size());
    for (std::size_t i = 0; i < read.unit.size(); ++i) {
        const std::size_t b = read.bin[i];
        out.lines[slot[b]++] = read.unit[i];
        Bin& bin = out.bins[static_cast<std::size_t>(occupied[b])];
        bin.radius_rad = std::min(bin.radius_rad, std::abs(read.unit[i].dot(bin.direction)));
    }
    // Rounded up a little, so that a bin is never wrongly taken as wholly inside or outside.
    for (Bin& bin : out.bins) {
        bin.radius_rad = std::acos(bin.radius_rad) + 1e-9;
        out.x.push_back(bin.direction.x());
        out.y.push_back(bin.direction.y());
        out.z.push_back(bin.direction.z());
    }
    return out;
}

// A window of half-angle w and, per bin, the |cos| to the bin's direction above which all its
// lines are inside (angle <= w - radius) and below which all are outside (angle > w + radius).
struct WindowBounds {
    double cos_window = 1.0;
    std::vector<double> cos_all_inside;
    std::vector<double> cos_all_outside;
};

WindowBounds Bounds(const std::vector<Bin>& bins, double window_rad) {
    WindowBounds bounds;
    bounds.cos_window = std::cos(window_rad);
    for (const Bin& bin : bins) {
        const double inner = window_rad - bin.radius_rad;
        const double outer = window_rad + bin.radius_rad;
        bounds.cos_all_inside.push_back(inner >= 0.0 ? std::cos(inner) : 2.0);  // never
        bounds.cos_all_outside.push_back(outer < std::numbers::pi / 2 ? std::cos(outer) : -1.0);
    }
    return bounds;
}

struct Window {
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    double count = 0.0;
};

// The lines within the window around `line`. The |cos| to every bin first, in one pass over the
// direction columns that the compiler vectorises; then the bins that are not wholly outside.
Window Gather(const BinnedLines& binned, const WindowBounds& bounds, const Eigen::Vector3d& line) {
    thread_local std::vector<double> cosines;
    const std::size_t n = binned.bins.size();
    cosines.resize(n);
    for (std::size_t b = 0; b < n; ++b) {
        cosines[b] =
            std::abs(binned.x[b] * line.x() + binned.y[b] * line.y() + binned.z[b] * line.z());
    }
    Window window;
    for (std::size_t b = 0; b < n; ++b) {
        if (cosines[b] < bounds.cos_all_outside[b]) continue;
        const Bin& bin = binned.bins[b];
        if (cosines[b] >= bounds.cos_all_inside[b]) {
            window.scatter += bin.scatter;
            window.count += bin.count();
            continue;
        }
        for (std::size_t i = bin.first; i < bin.last; ++i) {  // on the rim: line by line
            const Eigen::Vector3d& v = binned.lines[i];
            if (std::abs(v.dot(line)) < bounds.cos_window) continue;
            window.scatter.noalias() += v * v.transpose();
            window.count += 1.0;
        }
    }
    return window;
}

Eigen::Vector3d PrincipalAxis(const Eigen::Matrix3d& scatter) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(scatter);
    return solver.eigenvectors().col(2).normalized();
}

// Mean shift from `line` to the mode whose basin holds it, in place. Returns false, and stops,
// if the walk comes within `cos_known` of one of the `known` modes, onto which it is climbing (or
// next to which it would be dropped as the same cluster).
bool Climb(const BinnedLines& binned, const WindowBounds& bounds, Eigen::Vector3d& line,
           const std::vector<Eigen::Vector3d>& known = {}, double cos_known = 1.0) {
    for (int step = 0; step < kMaxIterations; ++step) {
        const Window window = Gather(binned, bounds, line);
        if (window.count <= 0.0) break;
        const Eigen::Vector3d next = PrincipalAxis(window.scatter);
        const bool converged = 1.0 - std::abs(next.dot(line)) < kConverged;
        line = next;
        const bool reached_known = std::any_of(known.begin(), known.end(), [&](const auto& k) {
            return std::abs(k.dot(line)) >= cos_known;
        });
        if (reached_known) return false;
        if (converged) break;
    }
    return true;
}

// The two windows of the search: the full one, and half of it for the last steps.
struct Windows {
    WindowBounds full;
    WindowBounds half;
};

// The mode reached from `seed`, and the lines within half its window. A window's mean line is
// pulled towards any other surface inside it (two planes 16 degrees apart are one mode whose mean
// lies between them); shifting on with half the window from there settles on the stronger
// surface's own normal. The count is over the whole window, the support the peak has.
struct ModeAndCore {
    OrientationMode mode;
    double core_count = 0.0;
};

std::optional<ModeAndCore> FindMode(const BinnedLines& binned, const Windows& windows,
                                    const Eigen::Vector3d& seed,
                                    const std::vector<Eigen::Vector3d>& known) {
    Eigen::Vector3d line = seed;
    if (!Climb(binned, windows.full, line, known, windows.half.cos_window)) return std::nullopt;
    Climb(binned, windows.half, line);
    if (line.z() < 0.0) line = -line;
    const auto count = static_cast<std::size_t>(Gather(binned, windows.full, line).count);
    return ModeAndCore{{line, count}, Gather(binned, windows.half, line).count};
}

// The uncovered bin with the most lines, or none.
std::optional<std::size_t> StrongestUncovered(const std::vector<Bin>& bins,
                                              const std::vector<char>& covered) {
    std::optional<std::size_t> best;
    for (std::size_t b = 0; b < bins.size(); ++b) {
        if (!covered[b] && (!best || bins[b].count() > bins[*best].count())) best = b;
    }
    return best;
}

// Keeps the strongest of every group of modes closer than the window: one cluster reached from
// two seeds.
std::vector<OrientationMode> SuppressWeakerNeighbours(std::vector<OrientationMode> modes,
                                                      double cos_window) {
    std::stable_sort(modes.begin(), modes.end(),
                     [](const auto& a, const auto& b) { return a.count > b.count; });
    std::vector<OrientationMode> kept;
    for (const OrientationMode& mode : modes) {
        const bool near_stronger = std::any_of(kept.begin(), kept.end(), [&](const auto& k) {
            return std::abs(k.line.dot(mode.line)) >= cos_window;
        });
        if (!near_stronger) kept.push_back(mode);
    }
    return kept;
}

}  // namespace

std::vector<OrientationMode> FindOrientationModes(std::span<const float> x,
                                                  std::span<const float> y,
                                                  std::span<const float> z, double window_rad) {
    if (x.size() != y.size() || x.size() != z.size()) {
        throw Error("FindOrientationModes: the x, y and z columns differ in length");
    }
    if (!(window_rad > 0.0 && window_rad <= std::numbers::pi / 4)) {
        throw ConfigError("FindOrientationModes: the window must be in (0, pi/4] radians");
    }
    const BinnedLines binned = BinLines(x, y, z);
    const std::vector<Bin>& bins = binned.bins;
    const Windows windows{Bounds(bins, window_rad), Bounds(bins, 0.5 * window_rad)};
    const double cos_window = windows.full.cos_window;
    const auto lines = static_cast<double>(binned.lines.size());
    // The lines no accepted mode explains (outside their windows). Spread evenly over the half
    // sphere (area 2 pi) they would put a fraction (1 - cos w) into a window and 4 / (pi kGrid^2)
    // into a bin (a square of the disc of area 2 pi): a window holding no more is no peak of
    // their density, and once no uncovered bin is denser than that, nothing is left to seed.
    // Measured against the unexplained lines, not all: a wall is a peak beside a ground that
    // holds 95% of the normals.
    double unexplained = lines;
    const double window_share = 1.0 - cos_window;
    const double bin_share = 4.0 / (std::numbers::pi * kGrid * kGrid);
    // A peak holds kMinPeakShare of all lines, kMinCoreShare of those in its core (half the
    // window), so the densest bin of its core at least their share per bin there: a weaker seed
    // leads to no peak, only to another mean shift through noise.
    const double core_share = 1.0 - std::cos(0.5 * window_rad);
    const double weakest_seed = kMinPeakShare * kMinCoreShare * lines * bin_share / core_share;
    std::vector<char> covered(bins.size(), 0);
    std::vector<char> explained(bins.size(), 0);
    std::vector<OrientationMode> modes;
    std::vector<Eigen::Vector3d> known;  // every mode reached, peak or not
    for (std::size_t seeds = 0; seeds < kMaxSeeds; ++seeds) {
        const std::optional<std::size_t> seed = StrongestUncovered(bins, covered);
        if (!seed || bins[*seed].count() <= std::max(bin_share * unexplained, weakest_seed)) {
            break;
        }
        // The seed's neighbours (within half a window) climb the same way: no walk of their own.
        for (std::size_t b = 0; b < bins.size(); ++b) {
            if (std::abs(bins[b].direction.dot(bins[*seed].direction)) >= windows.half.cos_window) {
                covered[b] = 1;
            }
        }
        covered[*seed] = 1;
        const std::optional<ModeAndCore> found =
            FindMode(binned, windows, bins[*seed].direction, known);
        if (!found) continue;
        const auto& [mode, core_count] = *found;
        known.push_back(mode.line);
        const auto count = static_cast<double>(mode.count);
        const bool peak = count > window_share * unexplained && count >= kMinPeakShare * lines &&
                          core_count >= kMinCoreShare * count;
        for (std::size_t b = 0; b < bins.size(); ++b) {
            if (std::abs(bins[b].direction.dot(mode.line)) < cos_window) continue;
            covered[b] = 1;
            if (peak && !explained[b]) {
                explained[b] = 1;
                unexplained -= bins[b].count();
            }
        }
        if (peak) modes.push_back(mode);
    }
    return SuppressWeakerNeighbours(std::move(modes), cos_window);
}

}  // namespace lidarloop::core

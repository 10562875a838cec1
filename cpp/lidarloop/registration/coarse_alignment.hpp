#pragma once

#include <complex>
#include <cstdint>
#include <memory>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/registration/prepared_scan.hpp"
#include "lidarloop/registration/verification_config.hpp"

namespace lidarloop::registration {

/// A planar pose hypothesis of the coarse search: T_match_query = Translation(x, y, 0) * Rz(yaw).
struct PlanarHypothesis {
    double yaw_rad = 0.0;
    Eigen::Vector2d translation_m = Eigen::Vector2d::Zero();
    double score = 0.0;  ///< correlation of the occupancy images at the peak (higher: better)
};

/// The yaws of T_match_query (radians) that another source of the pose allows a loop: within
/// half_width_rad of centre_rad (the odometry's gate), and with half_turn_too also of centre_rad
/// plus pi (the layouts', which repeat after half a turn). The default, and a window with a NaN,
/// is every yaw.
struct YawWindow {
    double centre_rad = 0.0;
    double half_width_rad = std::numbers::pi;
    bool half_turn_too = false;  ///< also the window around centre_rad + pi

    bool Whole() const;
    /// Whether `yaw_rad` lies within the window (angles wrapped).
    bool Contains(double yaw_rad) const;
};

/// The window the coarse search looks in for `allowed`: wider by two yaw steps, because a
/// peak's yaw is off by up to half a step and ICP turns the pose by a few degrees.
YawWindow SearchedYaws(const YawWindow& allowed, const CoarseConfig& config);

/// The query's side of the coarse search, shared by all its candidates: the spectrum of its
/// top-down structure image at each searched yaw, computed when a pair first needs it (two yaws
/// per transform), so that a query whose search stops early pays for the yaws it searched only.
class CoarseQuery {
public:
    /// For the yaws SearchedYaws of some of `windows` holds (the candidates' windows), of every
    /// yaw when `windows` is empty or one of them is whole.
    CoarseQuery(const SurfacePoints& query_structure, const CoarseConfig& config,
                const std::vector<YawWindow>& windows = {});
    ~CoarseQuery();
    CoarseQuery(CoarseQuery&&) noexcept;
    CoarseQuery& operator=(CoarseQuery&&) noexcept;

    const CoarseConfig& config() const { return config_; }
    int yaw_count() const { return static_cast<int>(wanted_.size()); }
    double YawOf(int index) const;
    /// Whether yaw `index` is one the windows hold (CoarseAlign throws for any other).
    bool Has(int index) const { return wanted_[static_cast<std::size_t>(index)]; }
    /// The conjugate spectrum of yaw `index`, computed on first use; thread-safe. Throws
    /// std::invalid_argument for a yaw it does not have.
    const std::vector<std::complex<float>>& spectrum(int index) const;
    /// Whether the spectrum of yaw `index` has been computed yet.
    bool Computed(int index) const;
    /// Cells of the correlation grid within max_translation_m (wrapped indices, row-major).
    const std::vector<std::uint32_t>& search_cells() const { return search_cells_; }
    /// The rows of the correlation grid the inverse transforms compute: those of the searched
    /// cells and the rows beside them (the peaks' refinement reads them), ascending. A plane of
    /// them is stored column by column (detail::Fft2dInverseRows).
    const std::vector<int>& computed_rows() const { return computed_rows_; }
    /// Where cell (x, y) of a computed row lies in such a plane; throws std::logic_error for a
    /// row not computed.
    std::size_t PositionOf(int x, int y) const;
    /// PositionOf of each of search_cells().
    const std::vector<std::uint32_t>& search_positions() const { return search_positions_; }

private:
    CoarseConfig config_;
    std::vector<std::uint32_t> search_cells_;
    std::vector<int> computed_rows_;
    std::vector<int> slot_of_row_;  // per grid row, its index in computed_rows_, or -1
    std::vector<std::uint32_t> search_positions_;
    std::vector<bool> wanted_;  // per yaw
    struct Spectra;             // the query's points and the spectra computed so far
    std::unique_ptr<Spectra> spectra_;
};

/// The top-down occupancy image of `points` after Rz(yaw_rad): grid_cells^2 values, row-major
/// (row = y cell), the sensor at the centre; 1 in every cell holding a point.
std::vector<float> OccupancyImage(const std::vector<Eigen::Vector3f>& points, double yaw_rad,
                                  const CoarseConfig& config);

/// The best distinct planar poses of the query in the match's frame, best first (at most
/// config.TotalHypotheses()): for every yaw, the translations (up to peaks_per_yaw, 3 cells
/// apart) that maximise the cross-correlation of the query's rotated structure image with the
/// match's (FFT), within max_translation_m, at the yaws SearchedYaws(`allowed`) holds; of a
/// window with a half turn (the layouts'), with CoarseConfig::better_half_turn_only, only the
/// half whose centre yaw correlates better, and the other centre's yaw. A yaw's peaks do not
/// depend on the window (peaks of equal score may come in another order).
/// Empty when either scan has no structure points. Throws std::invalid_argument when `query`
/// lacks a searched yaw (it was built for other windows). Thread-safe.
std::vector<PlanarHypothesis> CoarseAlign(const CoarseQuery& query,
                                          const SurfacePoints& match_structure,
                                          const YawWindow& allowed = {});

namespace detail {

/// Points' x and y as two columns: the layout in which the query's images at every yaw are
/// computed (one pass over the columns per yaw).
struct PlanarPoints {
    explicit PlanarPoints(const std::vector<Eigen::Vector3f>& points);
    std::vector<float> x, y;
};

/// OccupancyImage of the points, from the columns.
std::vector<float> OccupancyImage(const PlanarPoints& points, double yaw_rad,
                                  const CoarseConfig& config);

/// The best translations of one correlation plane over `search_cells` (row-major cells of the
/// n x n grid; cell search_cells[i] has the value values[positions[i]]), as CoarseAlign takes
/// them: the cell of the highest correlation rounded to a multiple of 0.5 (the first searched on
/// a tie), then the highest more than 3 cells (wrapped) from every one taken, up to `count`; only
/// cells above 0. In a place that repeats (a row of identical rooms, a colonnade) one yaw has
/// several peaks; the ambiguity test needs them all.
std::vector<std::uint32_t> PeakCells(const std::vector<float>& values,
                                     const std::vector<std::uint32_t>& search_cells,
                                     const std::vector<std::uint32_t>& positions, int n, int count);

}  // namespace detail

}  // namespace lidarloop::registration

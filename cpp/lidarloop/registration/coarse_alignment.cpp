
#include "lidarloop/registration/coarse_alignment.hpp"
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include "lidarloop/core/angles.hpp"
#include "lidarloop/core/detail/vector_clones.hpp"
#include "lidarloop/registration/detail/fft2d.hpp"

namespace lidarloop::registration {
namespace {

using Spectrum = std::vector<std::complex<float>>;

Spectrum ToSpectrum(const std::vector<float>& image, int n) {
    Spectrum spectrum(image.begin(), image.end());
    detail::Fft2dForward(spectrum, n);
    return spectrum;
}

// The match image, spread: a cell next to an occupied one scores half, so that a query cell one
// cell off (the yaw step, the cell grid) still counts.
std::vector<float> Spread(const std::vector<float>& image, int n) {
    std::vector<float> spread(image);
    auto at = [&](int x, int y) { return image[static_cast<std::size_t>(y * n + x)]; };
    for (int y = 1; y + 1 < n; ++y) {
        for (int x = 1; x + 1 < n; ++x) {
            const bool beside = at(x - 1, y) > 0.0F || at(x + 1, y) > 0.0F || at(x, y - 1) > 0.0F ||
                                at(x, y + 1) > 0.0F;
            if (beside) spread[static_cast<std::size_t>(y * n + x)] = std::max(at(x, y), 0.5F);
        }
    }
    return spread;
}

// The spectrum of two yaws' correlations in one: product = qa m + i qb m, where qa and qb are
// the query's (conjugate) spectra at two yaws and m the match's. Both correlations are real, so
// yaw b rides in the imaginary part. Written out: std::complex's product checks for NaN and does
// not vectorise.
LIDARLOOP_VECTOR_CLONES
void MultiplyPair(const Spectrum& qa, const Spectrum& qb, const Spectrum& m,
                  detail::SplitGrid& product) {
    for (std::size_t i = 0; i < m.size(); ++i) {
        const float mr = m[i].real(), mi = m[i].imag();
        const float ar = qa[i].real(), ai = qa[i].imag(), br = qb[i].real(), bi = qb[i].imag();
        product.re[i] = (ar * mr - ai * mi) - (br * mi + bi * mr);
        product.im[i] = (ar * mi + ai * mr) + (br * mr - bi * mi);
    }
}

// The signed shift of a wrapped correlation index.
int Signed(int index, int n) { return index < n / 2 ? index : index - n; }

// Sub-cell offset of a peak from the values beside it (a parabola through three samples).
double ParabolicOffset(double before, double at, double after) {
    const double curvature = before - 2.0 * at + after;
    if (curvature >= 0.0) return 0.0;
    return std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5);
}

// A correlation of a 0/1 query image with a 0/0.5/1 match image is a multiple of 0.5. Rounded to
// it, the FFT's rounding error is gone: equal correlations tie exactly (the first searched cell
// wins), so the hypotheses do not depend on how the FFT computed them. Non-negative images
// correlate above -0.25 even with that error, where truncating x + 0.5 rounds as std::round
// does, without a call into libm in the peak search's loop.
double Correlation(float value) {
    return static_cast<double>(static_cast<std::int64_t>(2.0F * value + 0.5F)) / 2.0;
}

// A plane value below this cannot round (Correlation) above `score`, a multiple of 0.5: the
// peak search skips most cells by one float comparison. Rounding gives more than `score` from
// `score` + 0.25 on; the margin covers the float arithmetic of Correlation and of this bound.
float SkipBelow(double score) {
    return static_cast<float>(score + 0.25 - (0.01 + 1e-6 * std::abs(score)));
}

// The peak at `cell` of one correlation plane (the query's computed rows, column by column),
// refined to sub-cell precision.
PlanarHypothesis PeakAt(const std::vector<float>& plane, std::uint32_t cell,
                        const CoarseQuery& query, double yaw_rad) {
    const int n = query.config().grid_cells;
    const int x = static_cast<int>(cell) % n, y = static_cast<int>(cell) / n;
    auto at = [&](int cx, int cy) {
        return Correlation(plane[query.PositionOf((cx + n) % n, (cy + n) % n)]);
    };
    const double score = at(x, y);
    const double fx = ParabolicOffset(at(x - 1, y), score, at(x + 1, y));
    const double fy = ParabolicOffset(at(x, y - 1), score, at(x, y + 1));
    return {yaw_rad, Eigen::Vector2d(Signed(x, n) + fx, Signed(y, n) + fy) * query.config().cell_m,
            score};
}

// Peaks of one correlation plane at most this many cells apart are one (detail::PeakCells).
constexpr int kPeakSeparationCells = 3;

// Cells apart on the wrapped correlation grid (the larger of the two axis distances).
int CellDistance(std::uint32_t a, std::uint32_t b, int n) {
    const int dx = std::abs(Signed((static_cast<int>(a % n) - static_cast<int>(b % n) + n) % n, n));
    const int dy = std::abs(Signed((static_cast<int>(a / n) - static_cast<int>(b / n) + n) % n, n));
    return std::max(dx, dy);
}

void AddPeaks(const std::vector<float>& plane, const CoarseQuery& query, double yaw_rad, int count,
              std::vector<PlanarHypothesis>& peaks) {
    for (const std::uint32_t cell :
         detail::PeakCells(plane, query.search_cells(), query.search_positions(),
                           query.config().grid_cells, count)) {
        peaks.push_back(PeakAt(plane, cell, query, yaw_rad));
    }
}

// The searched rows and the rows beside them (wrapped), ascending and unique.
std::vector<int> RowsWithNeighbors(const std::vector<int>& rows, int n) {
    std::vector<bool> needed(static_cast<std::size_t>(n), false);
    for (const int row : rows) {
        for (const int d : {-1, 0, 1}) needed[static_cast<std::size_t>((row + d + n) % n)] = true;
    }
    std::vector<int> result;
    for (int row = 0; row < n; ++row) {
        if (needed[static_cast<std::size_t>(row)]) result.push_back(row);
    }
    return result;
}

double YawDistance(double a_rad, double b_rad) {
    return std::abs(std::remainder(a_rad - b_rad, 2.0 * std::numbers::pi));
}

// Greedily keeps the best peaks that differ from every kept one in yaw or translation.
std::vector<PlanarHypothesis> Distinct(std::vector<PlanarHypothesis> peaks,
                                       const CoarseConfig& config) {
    // Stable: scores are multiples of 0.5 and tie often; tied peaks stay in yaw order, so the
    // hypotheses do not depend on the standard library's sort, nor on a yaw window's cut.
    std::stable_sort(peaks.begin(), peaks.end(),
                     [](const auto& a, const auto& b) { return a.score > b.score; });
    std::vector<PlanarHypothesis> kept;
    for (const auto& peak : peaks) {
        if (peak.score <= 0.0) break;
        const bool distinct = std::all_of(kept.begin(), kept.end(), [&](const auto& other) {
            return YawDistance(peak.yaw_rad, other.yaw_rad) >
                       2.5 * config.yaw_step_deg * core::kRadiansPerDegree ||
                   (peak.translation_m - other.translation_m).norm() > 3.0 * config.cell_m;
        });
        if (distinct) kept.push_back(peak);
        if (static_cast<int>(kept.size()) == config.TotalHypotheses()) break;
    }
    return kept;
}

// The yaw of the `index`-th of `yaws` equal steps around the circle, radians.
double YawAt(int index, int yaws) { return index * 2.0 * std::numbers::pi / yaws; }

// The yaws of `query` that some of `windows` holds, as SearchedYaws widens them.
std::vector<bool> YawsWithin(const std::vector<YawWindow>& windows, const CoarseConfig& config,
                             int yaws) {
    const bool every = windows.empty() || std::any_of(windows.begin(), windows.end(),
                                                      [](const auto& w) { return w.Whole(); });
    std::vector<bool> within(static_cast<std::size_t>(yaws), every);
    if (every) return within;
    for (const YawWindow& window : windows) {
        const YawWindow searched = SearchedYaws(window, config);
        for (int i = 0; i < yaws; ++i) {
            if (searched.Contains(YawAt(i, yaws))) within[static_cast<std::size_t>(i)] = true;
        }
    }
    return within;
}

}  // namespace

bool YawWindow::Whole() const {
    return !(half_width_rad < std::numbers::pi) || !std::isfinite(centre_rad);
}

bool YawWindow::Contains(double yaw_rad) const {
    return Whole() || YawDistance(yaw_rad, centre_rad) <= half_width_rad ||
           (half_turn_too && YawDistance(yaw_rad, centre_rad + std::numbers::pi) <= half_width_rad);
}

YawWindow SearchedYaws(const YawWindow& allowed, const CoarseConfig& config) {
    YawWindow searched = allowed;
    searched.half_width_rad += 2.0 * config.yaw_step_deg * core::kRadiansPerDegree;
    return searched;
}

std::vector<float> OccupancyImage(const std::vector<Eigen::Vector3f>& points, double yaw_rad,
                                  const CoarseConfig& config) {
    return detail::OccupancyImage(detail::PlanarPoints(points), yaw_rad, config);
}

struct CoarseQuery::Spectra {
    Spectra(const std::vector<Eigen::Vector3f>& points, int yaws)
        : planar(points),
          spectra(static_cast<std::size_t>(yaws)),
          pair_once(static_cast<std::size_t>(yaws + 1) / 2),
          pair_done(static_cast<std::size_t>(yaws + 1) / 2) {}
    detail::PlanarPoints planar;  // read once per yaw
    std::vector<Spectrum> spectra;
    // Yaws 2k and 2k + 1 share a transform (the images are real: detail::Fft2dForwardRealPair),
    // a fixed pairing so that a yaw's spectrum does not depend on which pair asked first.
    std::vector<std::once_flag> pair_once;
    std::vector<std::atomic<bool>> pair_done;
};

CoarseQuery::CoarseQuery(const SurfacePoints& query_structure, const CoarseConfig& config,
                         const std::vector<YawWindow>& windows)
    : config_(config) {
    const int n = config.grid_cells;
    const double max_cells = config.max_translation_m / config.cell_m;
    std::vector<int> searched_rows;
    for (int y = 0; y < n; ++y) {
        bool row_searched = false;
        for (int x = 0; x < n; ++x) {
            if (std::hypot(Signed(x, n), Signed(y, n)) > max_cells) continue;
            search_cells_.push_back(static_cast<std::uint32_t>(y * n + x));
            row_searched = true;
        }
        if (row_searched) searched_rows.push_back(y);
    }
    // The parabolic refinement reads the rows beside a peak too.
    computed_rows_ = RowsWithNeighbors(searched_rows, n);
    slot_of_row_.assign(static_cast<std::size_t>(n), -1);
    for (std::size_t j = 0; j < computed_rows_.size(); ++j)
        slot_of_row_[static_cast<std::size_t>(computed_rows_[j])] = static_cast<int>(j);
    for (const std::uint32_t cell : search_cells_) {
        const int x = static_cast<int>(cell) % n, y = static_cast<int>(cell) / n;
        search_positions_.push_back(static_cast<std::uint32_t>(PositionOf(x, y)));
    }
    const int yaws = static_cast<int>(std::lround(360.0 / config.yaw_step_deg));
    wanted_ = YawsWithin(windows, config, yaws);
    spectra_ = std::make_unique<Spectra>(query_structure.points(), yaws);
}

CoarseQuery::~CoarseQuery() = default;
CoarseQuery::CoarseQuery(CoarseQuery&&) noexcept = default;
CoarseQuery& CoarseQuery::operator=(CoarseQuery&&) noexcept = default;

const std::vector<std::complex<float>>& CoarseQuery::spectrum(int index) const {
    if (index < 0 || index >= yaw_count() || !Has(index))
        throw std::invalid_argument("CoarseAlign: the query's images lack a searched yaw");
    const auto pair = static_cast<std::size_t>(index / 2);
    std::call_once(spectra_->pair_once[pair], [&] {
        const int n = config_.grid_cells;
        const int a = 2 * (index / 2), b = std::min(a + 1, yaw_count() - 1);
        const auto image_at = [&](int i) {
            return detail::OccupancyImage(spectra_->planar, YawOf(i), config_);
        };
        auto& spectra = spectra_->spectra;
        // The last of an odd count has no partner: its twin output goes elsewhere, not into the
        // same vector (the transform's outputs must not alias).
        Spectrum twin;
        detail::Fft2dForwardRealPair(image_at(a), image_at(b), n, spectra[a],
                                     b == a ? twin : spectra[b]);
        const auto conjugate = [&](int i) {
            for (auto& value : spectra[static_cast<std::size_t>(i)]) value = std::conj(value);
        };
        conjugate(a);
        if (b != a) conjugate(b);
        spectra_->pair_done[pair].store(true, std::memory_order_release);
    });
    return spectra_->spectra[static_cast<std::size_t>(index)];
}

bool CoarseQuery::Computed(int index) const {
    return spectra_->pair_done[static_cast<std::size_t>(index / 2)].load(std::memory_order_acquire);
}

double CoarseQuery::YawOf(int index) const { return YawAt(index, yaw_count()); }

std::size_t CoarseQuery::PositionOf(int x, int y) const {
    const int slot = slot_of_row_[static_cast<std::size_t>(y)];
    if (slot < 0) throw std::logic_error("CoarseQuery: row " + std::to_string(y) + " not computed");
    return static_cast<std::size_t>(x) * computed_rows_.size() + static_cast<std::size_t>(slot);
}

namespace {

// The correlations of the yaws at `indices` with the match, two per inverse transform, and their
// peaks into `peaks`.
void CorrelateYaws(const CoarseQuery& query, const Spectrum& match, const std::vector<int>& indices,
                   std::vector<PlanarHypothesis>& peaks) {
    const CoarseConfig& config = query.config();
    const int n = config.grid_cells;
    detail::SplitGrid product{std::vector<float>(match.size()), std::vector<float>(match.size())};
    detail::SplitGrid correlations;  // the computed rows, column by column
    for (std::size_t k = 0; k < indices.size(); k += 2) {
        const int a = indices[k];
        const bool pair = k + 1 < indices.size();
        const int b = pair ? indices[k + 1] : a;
        MultiplyPair(query.spectrum(a), query.spectrum(b), match, product);
        detail::Fft2dInverseRows(product, n, query.computed_rows(), correlations);
        AddPeaks(correlations.re, query, query.YawOf(a), config.peaks_per_yaw, peaks);
        if (pair) AddPeaks(correlations.im, query, query.YawOf(b), config.peaks_per_yaw, peaks);
    }
}

int NearestYaw(const CoarseQuery& query, double yaw_rad) {
    const int yaws = query.yaw_count();
    const double steps = yaw_rad / (2.0 * std::numbers::pi) * yaws;
    return static_cast<int>(((std::lround(steps) % yaws) + yaws) % yaws);
}

// The best score of the peaks at `yaw_rad`.
double BestScoreAt(const std::vector<PlanarHypothesis>& peaks, double yaw_rad) {
    double best = 0.0;
    for (const auto& peak : peaks) {
        if (peak.yaw_rad == yaw_rad) best = std::max(best, peak.score);
    }
    return best;
}

// The windows of `allowed` to search: with a half turn and CoarseConfig::better_half_turn_only,
// the one whose centre yaw correlates better (both on a tie). Both centres are correlated in one
// transform, their peaks go into `peaks` and their indices into `done`.
std::vector<YawWindow> HalvesToSearch(const CoarseQuery& query, const Spectrum& match,
                                      const YawWindow& allowed,
                                      std::vector<PlanarHypothesis>& peaks,
                                      std::vector<int>& done) {
    if (!allowed.half_turn_too || allowed.Whole() || !query.config().better_half_turn_only)
        return {allowed};
    const YawWindow half{allowed.centre_rad, allowed.half_width_rad, false};
    const YawWindow other{allowed.centre_rad + std::numbers::pi, allowed.half_width_rad, false};
    done = {NearestYaw(query, half.centre_rad), NearestYaw(query, other.centre_rad)};
    // Both centres' peaks stay: the worse one may still be a rival of the better's pose.
    CorrelateYaws(query, match, done, peaks);
    const double centre_score = BestScoreAt(peaks, query.YawOf(done[0]));
    const double opposite_score = BestScoreAt(peaks, query.YawOf(done[1]));
    if (centre_score == opposite_score) return {allowed};
    return {centre_score > opposite_score ? half : other};
}

}  // namespace

std::vector<PlanarHypothesis> CoarseAlign(const CoarseQuery& query,
                                          const SurfacePoints& match_structure,
                                          const YawWindow& allowed) {
    const CoarseConfig& config = query.config();
    const int n = config.grid_cells;
    if (match_structure.size() == 0 || query.yaw_count() == 0) return {};
    const Spectrum match =
        ToSpectrum(Spread(OccupancyImage(match_structure.points(), 0.0, config), n), n);
    std::vector<PlanarHypothesis> peaks;
    std::vector<int> done;
    const std::vector<YawWindow> windows = HalvesToSearch(query, match, allowed, peaks, done);
    const std::vector<bool> wanted = YawsWithin(windows, config, query.yaw_count());
    std::vector<int> indices;
    for (int i = 0; i < query.yaw_count(); ++i) {
        if (wanted[static_cast<std::size_t>(i)] &&
            std::find(done.begin(), done.end(), i) == done.end())
            indices.push_back(i);
    }
    CorrelateYaws(query, match, indices, peaks);
    // Tied peaks in yaw order, whichever yaw was correlated first (Distinct).
    std::stable_sort(peaks.begin(), peaks.end(),
                     [](const auto& a, const auto& b) { return a.yaw_rad < b.yaw_rad; });
    return Distinct(std::move(peaks), config);
}

namespace detail {

PlanarPoints::PlanarPoints(const std::vector<Eigen::Vector3f>& points) {
    x.reserve(points.size());
    y.reserve(points.size());
    for (const auto& point : points) x.push_back(point.x()), y.push_back(point.y());
}

namespace {

// Per point, its image cell after the rotation (c -s; s c), or n^2 (a spare cell) outside the
// image. One branch-free pass over columns, so that it vectorises; the products and sums are
// those of Eigen's Rotation2Df, so the cells are the same as rotating each point with it.
LIDARLOOP_VECTOR_CLONES
void CellsOf(const PlanarPoints& points, float c, float s, float inverse_cell, int n,
             std::vector<std::int32_t>& cells) {
    const std::size_t count = points.x.size();
    cells.resize(count);
    const float* __restrict xs = points.x.data();
    const float* __restrict ys = points.y.data();
    std::int32_t* __restrict out = cells.data();
    for (std::size_t i = 0; i < count; ++i) {
        const float rotated_x = c * xs[i] + (-s) * ys[i];
        const float rotated_y = s * xs[i] + c * ys[i];
        const auto cx = static_cast<std::int32_t>(std::floor(rotated_x * inverse_cell)) + n / 2;
        const auto cy = static_cast<std::int32_t>(std::floor(rotated_y * inverse_cell)) + n / 2;
        // Negative cells wrap to large unsigned ones; & instead of && keeps the loop branch-free.
        const bool inside = (static_cast<std::uint32_t>(cx) < static_cast<std::uint32_t>(n)) &
                            (static_cast<std::uint32_t>(cy) < static_cast<std::uint32_t>(n));
        out[i] = inside ? cy * n + cx : n * n;
    }
}

}  // namespace

std::vector<float> OccupancyImage(const PlanarPoints& points, double yaw_rad,
                                  const CoarseConfig& config) {
    const int n = config.grid_cells;
    const Eigen::Matrix2f rotation =
        Eigen::Rotation2Df(static_cast<float>(yaw_rad)).toRotationMatrix();
    thread_local std::vector<std::int32_t> cells;
    CellsOf(points, rotation(0, 0), rotation(1, 0), static_cast<float>(1.0 / config.cell_m), n,
            cells);
    std::vector<float> image(static_cast<std::size_t>(n * n) + 1, 0.0F);
    for (const std::int32_t cell : cells) image[static_cast<std::size_t>(cell)] = 1.0F;
    image.pop_back();  // the spare cell
    return image;
}

std::vector<std::uint32_t> PeakCells(const std::vector<float>& values,
                                     const std::vector<std::uint32_t>& search_cells,
                                     const std::vector<std::uint32_t>& positions, int n,
                                     int count) {
    std::vector<std::uint32_t> taken;
    for (int k = 0; k < count; ++k) {
        double best_score = 0.0;
        float skip_below = SkipBelow(best_score);
        std::optional<std::uint32_t> best;
        for (std::size_t i = 0; i < search_cells.size(); ++i) {
            const float correlation = values[positions[i]];
            if (correlation < skip_below) continue;
            const std::uint32_t cell = search_cells[i];
            const double value = Correlation(correlation);
            if (value <= best_score) continue;
            const bool apart = std::all_of(taken.begin(), taken.end(), [&](std::uint32_t t) {
                return CellDistance(cell, t, n) > kPeakSeparationCells;
            });
            if (apart) best_score = value, skip_below = SkipBelow(value), best = cell;
        }
        if (!best) break;
        taken.push_back(*best);
    }
    return taken;
}

}  // namespace detail

}  // namespace lidarloop::registration

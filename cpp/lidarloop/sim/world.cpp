#include "lidarloop/sim/world.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/sim/detail/intersect.hpp"

namespace lidarloop::sim {
namespace {

constexpr double kTinyRayComponent = 1e-12;
constexpr double kMaxCells = 1 << 24;  // 16M cells: a coarser grid beyond that

}  // namespace

World::World(Terrain ground, double ceiling_height_m, std::vector<Shape> objects,
             double grid_cell_m)
    : ground_(std::move(ground)),
      ceiling_height_m_(ceiling_height_m),
      objects_(std::move(objects)),
      cell_m_(grid_cell_m) {
    if (!(grid_cell_m > 0.0) || !std::isfinite(grid_cell_m)) {
        throw core::ConfigError("world grid cell size must be > 0 m, got " +
                                core::NumberText(grid_cell_m));
    }
    if (!(ceiling_height_m >= 0.0) || !std::isfinite(ceiling_height_m)) {
        throw core::ConfigError("world ceiling height must be >= 0 m (0: open sky), got " +
                                core::NumberText(ceiling_height_m));
    }
    box_cos_sin_.resize(objects_.size(), Eigen::Vector2d(1.0, 0.0));
    for (std::size_t i = 0; i < objects_.size(); ++i) {
        if (const Box* box = std::get_if<Box>(&objects_[i])) {
            box_cos_sin_[i] = {std::cos(box->yaw_rad), std::sin(box->yaw_rad)};
        }
    }
    BuildGrid();
}

void World::BuildGrid() {
    if (objects_.empty()) return;
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(kNoHit);
    Eigen::Vector2d hi = Eigen::Vector2d::Constant(-kNoHit);
    std::vector<Aabb> bounds;
    bounds.reserve(objects_.size());
    for (const auto& object : objects_) {
        bounds.push_back(Bounds(object));
        lo = lo.cwiseMin(bounds.back().min_m.head<2>());
        hi = hi.cwiseMax(bounds.back().max_m.head<2>());
    }
    const Eigen::Vector2d size = hi - lo;
    while ((size.x() / cell_m_ + 1.0) * (size.y() / cell_m_ + 1.0) > kMaxCells) cell_m_ *= 2.0;
    grid_origin_m_ = lo;
    nx_ = std::max(1, static_cast<int>(std::ceil(size.x() / cell_m_)));
    ny_ = std::max(1, static_cast<int>(std::ceil(size.y() / cell_m_)));
    const auto cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
    cell_top_m_.assign(cells, -kNoHit);
    // Two passes over the objects' cell ranges: count, then fill (compressed rows).
    const auto cell_range = [&](const Aabb& box, int axis, int n) {
        const double origin = grid_origin_m_[axis];
        const int first = static_cast<int>(std::floor((box.min_m[axis] - origin) / cell_m_));
        const int last = static_cast<int>(std::floor((box.max_m[axis] - origin) / cell_m_));
        return std::pair{std::clamp(first, 0, n - 1), std::clamp(last, 0, n - 1)};
    };
    std::vector<std::uint32_t> counts(cells + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
        for (std::size_t i = 0; i < objects_.size(); ++i) {
            const auto [x0, x1] = cell_range(bounds[i], 0, nx_);
            const auto [y0, y1] = cell_range(bounds[i], 1, ny_);
            for (int y = y0; y <= y1; ++y) {
                for (int x = x0; x <= x1; ++x) {
                    const std::size_t cell = static_cast<std::size_t>(y) * nx_ + x;
                    if (pass == 0) {
                        ++counts[cell + 1];
                        cell_top_m_[cell] = std::max(cell_top_m_[cell], bounds[i].max_m.z());
                    } else {
                        cell_items_[counts[cell]++] = static_cast<std::uint32_t>(i);
                    }
                }
            }
        }
        if (pass == 0) {
            for (std::size_t c = 0; c < cells; ++c) counts[c + 1] += counts[c];
            cell_begin_ = counts;
            cell_items_.resize(counts.back());
        }
    }
}

double World::IntersectObject(const Ray& ray, std::uint32_t index) const {
    const Shape& shape = objects_[index];
    if (const Box* box = std::get_if<Box>(&shape)) {
        const Eigen::Vector2d& cs = box_cos_sin_[index];
        return detail::IntersectBox(ray, *box, cs.x(), cs.y());
    }
    return Intersect(ray, shape);
}

double World::CastSurfaces(const Ray& ray, double max_range_m) const {
    double best = ground_.Intersect(ray, 0.0, /*from_below=*/false, max_range_m);
    if (ceiling_height_m_ > 0.0) {
        best = std::min(best, ground_.Intersect(ray, ceiling_height_m_, /*from_below=*/true,
                                                std::min(best, max_range_m)));
    }
    return best;
}

bool World::ClipToGrid(const Ray& ray, double& t_in, double& t_out) const {
    const int n[2] = {nx_, ny_};
    for (int axis = 0; axis < 2; ++axis) {
        const double lo = grid_origin_m_[axis];
        const double hi = lo + n[axis] * cell_m_;
        const double o = ray.origin[axis];
        const double d = ray.direction[axis];
        if (std::abs(d) < kTinyRayComponent) {
            if (o < lo || o > hi) return false;
            continue;
        }
        const double ta = (lo - o) / d;
        const double tb = (hi - o) / d;
        t_in = std::max(t_in, std::min(ta, tb));
        t_out = std::min(t_out, std::max(ta, tb));
    }
    return t_in <= t_out;
}

double World::CastObjects(const Ray& ray, double max_range_m) const {
    double t_in = 0.0;
    double t_out = max_range_m;
    if (cell_items_.empty() || !ClipToGrid(ray, t_in, t_out)) return kNoHit;
    // Walk the cells from the entry point (Amanatides and Woo 1987).
    const Eigen::Vector3d& o = ray.origin;
    const Eigen::Vector3d& d = ray.direction;
    const int n[2] = {nx_, ny_};
    int cell[2];
    int step[2];
    double t_next[2];
    double t_delta[2];
    for (int axis = 0; axis < 2; ++axis) {
        const double origin = grid_origin_m_[axis];
        const double p = o[axis] + t_in * d[axis];
        cell[axis] =
            std::clamp(static_cast<int>(std::floor((p - origin) / cell_m_)), 0, n[axis] - 1);
        step[axis] = std::abs(d[axis]) < kTinyRayComponent ? 0 : (d[axis] > 0.0 ? 1 : -1);
        const double boundary = origin + (cell[axis] + (step[axis] > 0 ? 1 : 0)) * cell_m_;
        t_next[axis] = step[axis] == 0 ? kNoHit : (boundary - o[axis]) / d[axis];
        t_delta[axis] = step[axis] == 0 ? kNoHit : cell_m_ / std::abs(d[axis]);
    }
    double best = kNoHit;
    double t = t_in;
    while (true) {
        const double t_exit = std::min({t_next[0], t_next[1], t_out});
        const std::size_t c = static_cast<std::size_t>(cell[1]) * nx_ + cell[0];
        // Cells whose objects all lie below the ray are skipped.
        if (o.z() + d.z() * (d.z() > 0.0 ? t : t_exit) <= cell_top_m_[c]) {
            for (std::uint32_t k = cell_begin_[c]; k < cell_begin_[c + 1]; ++k) {
                best = std::min(best, IntersectObject(ray, cell_items_[k]));
            }
        }
        // A hit inside this cell cannot be beaten by objects met later.
        if (best <= t_exit || t_exit >= t_out) break;
        const int axis = t_next[0] < t_next[1] ? 0 : 1;
        cell[axis] += step[axis];
        if (cell[axis] < 0 || cell[axis] >= n[axis]) break;
        t = t_next[axis];
        t_next[axis] += t_delta[axis];
    }
    return best <= max_range_m ? best : kNoHit;
}

double World::CastRay(const Ray& ray, double max_range_m) const {
    const double surface = CastSurfaces(ray, max_range_m);
    return std::min(surface, CastObjects(ray, std::min(surface, max_range_m)));
}

double World::CastRayBruteForce(const Ray& ray, double max_range_m) const {
    double best = CastSurfaces(ray, max_range_m);
    for (const auto& object : objects_) best = std::min(best, Intersect(ray, object));
    return best <= max_range_m ? best : kNoHit;
}

bool World::IsFree(const Eigen::Vector3d& point_m, double clearance_m) const {
    const double ground = ground_.Height(point_m.x(), point_m.y());
    if (point_m.z() <= ground) return false;
    if (ceiling_height_m_ > 0.0 && point_m.z() >= ground + ceiling_height_m_) return false;
    if (cell_items_.empty()) return true;
    const auto index = [&](int axis, double value, int n) {
        const int i = static_cast<int>(std::floor((value - grid_origin_m_[axis]) / cell_m_));
        return std::clamp(i, 0, n - 1);
    };
    const int x0 = index(0, point_m.x() - clearance_m, nx_);
    const int x1 = index(0, point_m.x() + clearance_m, nx_);
    const int y0 = index(1, point_m.y() - clearance_m, ny_);
    const int y1 = index(1, point_m.y() + clearance_m, ny_);
    for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
            const std::size_t c = static_cast<std::size_t>(y) * nx_ + x;
            for (std::uint32_t k = cell_begin_[c]; k < cell_begin_[c + 1]; ++k) {
                if (Contains(objects_[cell_items_[k]], point_m, clearance_m)) return false;
            }
        }
    }
    return true;
}

}  // namespace lidarloop::sim

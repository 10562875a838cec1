#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/sim/shapes.hpp"
#include "lidarloop/sim/terrain.hpp"

namespace lidarloop::sim {

/// A simulated environment in the world frame (metres, z up): a ground surface, an optional
/// ceiling at a fixed height above it (tunnels, indoor floors), and solid objects. Ray casting
/// goes through a uniform 2-D grid over x-y whose cells list the objects overlapping them, walked
/// cell by cell along the ray (Amanatides and Woo 1987), so a ray tests only the objects near its
/// path. Immutable after construction; every member function is thread-safe.
class World {
public:
    /// `ceiling_height_m` 0 means open sky. `grid_cell_m` (> 0) is the side of a grid cell; a few
    /// metres suits streets, about 1 m suits rooms. Throws core::ConfigError for a cell size <= 0
    /// or a negative ceiling height.
    World(Terrain ground, double ceiling_height_m, std::vector<Shape> objects,
          double grid_cell_m = 4.0);

    /// Range (metres) to the first surface along `ray` (unit direction) within max_range_m, or
    /// kNoHit.
    double CastRay(const Ray& ray, double max_range_m) const;

    /// CastRay by testing every object, without the grid: the reference for tests.
    double CastRayBruteForce(const Ray& ray, double max_range_m) const;

    /// True when `point_m` is above the ground, below the ceiling and at least `clearance_m` away
    /// from every object (objects grown by the clearance, see Contains).
    bool IsFree(const Eigen::Vector3d& point_m, double clearance_m) const;

    const Terrain& ground() const { return ground_; }
    /// Height of the ceiling above the ground, metres; 0 for open sky.
    double ceiling_height_m() const { return ceiling_height_m_; }
    const std::vector<Shape>& objects() const { return objects_; }
    double grid_cell_m() const { return cell_m_; }

private:
    double CastSurfaces(const Ray& ray, double max_range_m) const;
    double CastObjects(const Ray& ray, double max_range_m) const;
    // Narrows [t_in, t_out] to the part of the ray over the grid; false when it misses it.
    bool ClipToGrid(const Ray& ray, double& t_in, double& t_out) const;
    double IntersectObject(const Ray& ray, std::uint32_t index) const;
    void BuildGrid();

    Terrain ground_;
    double ceiling_height_m_ = 0.0;
    std::vector<Shape> objects_;
    std::vector<Eigen::Vector2d> box_cos_sin_;  // per object; used for boxes only
    double cell_m_ = 4.0;
    Eigen::Vector2d grid_origin_m_ = Eigen::Vector2d::Zero();
    int nx_ = 0;
    int ny_ = 0;
    std::vector<std::uint32_t> cell_begin_;  // CSR: items of cell c are [begin[c], begin[c+1])
    std::vector<std::uint32_t> cell_items_;
    std::vector<double> cell_top_m_;  // highest object point in the cell; rays above skip it
};

}  // namespace lidarloop::sim

#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "lidarloop/core/ndt/ndt_cells.hpp"

namespace lidarloop::core {

/// Shape classes of an NDT cell (Magnusson II-B).
enum class CellShape : std::uint8_t { kSpherical, kPlanar, kLinear, kDegenerate };

/// The shape of one covariance and the axis that carries its orientation.
struct CellShapeInfo {
    CellShape shape = CellShape::kDegenerate;
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< planar: normal e3; linear: e1
    double l2_over_l1 = 0.0;                          ///< for spherical sub-classes
};

/// Classifies a covariance by its sorted eigenvalues l1 >= l2 >= l3: linear if l2/l1 < t_e,
/// planar if not linear and l3/l2 < t_e, spherical otherwise. A covariance with l1 ~ 0 (all
/// points equal) or a non-finite entry is kDegenerate. The axis of a spherical or degenerate
/// covariance is +z. Eigenvalues by the closed form of eigen3x3.hpp (error <= 1e-8 l1).
CellShapeInfo ClassifyCovariance(const Eigen::Matrix3d& covariance_m2, double t_e);

/// ClassifyCovariance of every cell of `cells`, as columns; entry i belongs to cell i. The same
/// arithmetic as ClassifyCovariance, so the results are identical, but branch-free over arrays so
/// that it runs vectorised (AVX2 where the CPU has it, chosen at load time): the hot loop of the
/// NDT descriptor.
struct CellShapeColumns {
    std::vector<CellShape> shape;
    std::vector<double> l2_over_l1;
    std::vector<double> axis_x, axis_y, axis_z;  ///< unit; +z for spherical and degenerate

    std::size_t size() const { return shape.size(); }
};
void ClassifyCells(const NdtCellColumns& cells, double t_e, CellShapeColumns& shapes);

}  // namespace lidarloop::core

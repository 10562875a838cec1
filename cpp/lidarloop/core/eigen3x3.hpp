#pragma once

#include <Eigen/Core>

namespace lidarloop::core {

/// Eigenvalues of a symmetric 3x3 matrix in descending order (l1 >= l2 >= l3), by the closed
/// trigonometric form of the characteristic cubic (Smith 1961). Absolute error below 1e-10 * l1
/// (tested against Eigen's iterative solver), ample for ratios compared with t_e ~ 0.1. Only the
/// upper triangle is read.
Eigen::Vector3d SymmetricEigenvaluesDescending(const Eigen::Matrix3d& a);

/// A unit eigenvector of the symmetric matrix `a` for its eigenvalue `lambda`, from the largest
/// cross product of two rows of (a - lambda I). Accurate when lambda is well separated from the
/// other eigenvalues (for NDT shapes the separation is at least 1/t_e); for a repeated
/// eigenvalue it returns some unit vector of the eigenspace, computed by Eigen's solver.
Eigen::Vector3d SymmetricEigenvector(const Eigen::Matrix3d& a, double lambda);

}  // namespace lidarloop::core

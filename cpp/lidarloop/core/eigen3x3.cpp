#include "lidarloop/core/eigen3x3.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

namespace lidarloop::core {

Eigen::Vector3d SymmetricEigenvaluesDescending(const Eigen::Matrix3d& a) {
    const double off_diagonal = a(0, 1) * a(0, 1) + a(0, 2) * a(0, 2) + a(1, 2) * a(1, 2);
    if (off_diagonal == 0.0) {
        Eigen::Vector3d d = a.diagonal();
        std::sort(d.data(), d.data() + 3, std::greater<>());
        return d;
    }
    // Shift by the mean eigenvalue q and scale by p so that B = (A - qI)/p has eigenvalues
    // 2 cos(phi + 2 pi k / 3), with cos(3 phi) = det(B) / 2.
    const double q = a.trace() / 3.0;
    const double d0 = a(0, 0) - q;
    const double d1 = a(1, 1) - q;
    const double d2 = a(2, 2) - q;
    const double p = std::sqrt((d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * off_diagonal) / 6.0);
    Eigen::Matrix3d b = a.selfadjointView<Eigen::Upper>();
    b.diagonal() -= Eigen::Vector3d::Constant(q);
    b /= p;
    const double half_det = std::clamp(b.determinant() / 2.0, -1.0, 1.0);
    const double phi = std::acos(half_det) / 3.0;
    const double l1 = q + 2.0 * p * std::cos(phi);
    const double l3 = q + 2.0 * p * std::cos(phi + 2.0 * M_PI / 3.0);
    return {l1, 3.0 * q - l1 - l3, l3};
}

Eigen::Vector3d SymmetricEigenvector(const Eigen::Matrix3d& a, double lambda) {
    Eigen::Matrix3d shifted = a.selfadjointView<Eigen::Upper>();
    shifted.diagonal() -= Eigen::Vector3d::Constant(lambda);
    // The eigenvector is orthogonal to every row of (A - lambda I); the cross product of the two
    // most independent rows gives it with the least cancellation.
    const Eigen::Vector3d candidates[3] = {shifted.row(0).cross(shifted.row(1)),
                                           shifted.row(0).cross(shifted.row(2)),
                                           shifted.row(1).cross(shifted.row(2))};
    const Eigen::Vector3d* best = &candidates[0];
    for (const Eigen::Vector3d& c : candidates) {
        if (c.squaredNorm() > best->squaredNorm()) best = &c;
    }
    const double scale = shifted.cwiseAbs().maxCoeff();
    if (best->squaredNorm() > 1e-20 * scale * scale * scale * scale) return best->normalized();
    // Repeated eigenvalue: (A - lambda I) has rank < 2 and any vector of its kernel will do.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(a);
    Eigen::Index closest = 0;
    (solver.eigenvalues().array() - lambda).abs().minCoeff(&closest);
    return solver.eigenvectors().col(closest);
}

}  // namespace lidarloop::core

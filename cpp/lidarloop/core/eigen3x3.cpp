#include "lidarloop/core/eigen3x3.hpp"

#include <Eigen/Eigenvalues>

namespace lidarloop::core {

Eigen::Vector3d SymmetricEigenvector(const Eigen::Matrix3d& a, double lambda) {
    // The eigenvector is orthogonal to every row of (A - lambda I); the cross product of the two
    // most independent rows gives it with the least cancellation.
    const Eigen::Vector3d r0(a(0, 0) - lambda, a(0, 1), a(0, 2));
    const Eigen::Vector3d r1(a(0, 1), a(1, 1) - lambda, a(1, 2));
    const Eigen::Vector3d r2(a(0, 2), a(1, 2), a(2, 2) - lambda);
    const Eigen::Vector3d c01 = r0.cross(r1);
    const Eigen::Vector3d c02 = r0.cross(r2);
    const Eigen::Vector3d c12 = r1.cross(r2);
    const double n01 = c01.squaredNorm();
    const double n02 = c02.squaredNorm();
    const double n12 = c12.squaredNorm();
    const Eigen::Vector3d& best = n01 >= n02 ? (n01 >= n12 ? c01 : c12) : (n02 >= n12 ? c02 : c12);
    const double best_norm2 = std::max({n01, n02, n12});
    const double scale =
        std::max({r0.cwiseAbs().maxCoeff(), r1.cwiseAbs().maxCoeff(), std::abs(r2.z())});
    if (best_norm2 > 1e-20 * scale * scale * scale * scale) return best / std::sqrt(best_norm2);
    // Repeated eigenvalue: (A - lambda I) has rank < 2 and any vector of its kernel will do.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(
        Eigen::Matrix3d(a.selfadjointView<Eigen::Upper>()));
    Eigen::Index closest = 0;
    (solver.eigenvalues().array() - lambda).abs().minCoeff(&closest);
    return solver.eigenvectors().col(closest);
}

}  // namespace lidarloop::core

#pragma once

#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace lidarloop::core {

namespace detail {

// acos(x) for x in [-1, 1] without a library call: Abramowitz & Stegun 4.4.46,
// acos(|x|) = sqrt(1 - |x|) * P7(|x|), absolute error below 2.2e-8 (tested). Branch-free, so
// the compiler can overlap consecutive calls; glibc's acos is exact but several times slower.
inline double AcosApprox(double x) {
    const double a = std::abs(x);
    double p = -0.0012624911;
    p = p * a + 0.0066700901;
    p = p * a - 0.0170881256;
    p = p * a + 0.0308918810;
    p = p * a - 0.0501743046;
    p = p * a + 0.0889789874;
    p = p * a - 0.2145988016;
    p = p * a + 1.5707963050;
    const double r = std::sqrt(1.0 - a) * p;
    return x < 0.0 ? std::numbers::pi - r : r;
}

// cos and sin of t in [-pi/6, pi/6] by their Taylor series to t^12 and t^13 (error < 1e-15).
inline void CosSinSmall(double t, double& c, double& s) {
    const double t2 = t * t;
    c = 1.0 +
        t2 * (-1.0 / 2 +
              t2 * (1.0 / 24 + t2 * (-1.0 / 720 +
                                     t2 * (1.0 / 40320 + t2 * (-1.0 / 3628800 + t2 / 479001600)))));
    s = t * (1.0 + t2 * (-1.0 / 6 +
                         t2 * (1.0 / 120 + t2 * (-1.0 / 5040 +
                                                 t2 * (1.0 / 362880 + t2 * (-1.0 / 39916800 +
                                                                            t2 / 6227020800.0))))));
}

struct Eigenvalues3 {
    double l1, l2, l3;  // descending
};

// The eigenvalues of the symmetric matrix with upper triangle (a00 a01 a02; a11 a12; a22).
// Written with selects on values only (no std::min, no branch), so that a loop over many
// matrices vectorises; see SymmetricEigenvaluesDescending.
inline Eigenvalues3 SymmetricEigenvalues(double a00, double a01, double a02, double a11, double a12,
                                         double a22) {
    const double off_diagonal = a01 * a01 + a02 * a02 + a12 * a12;
    // Shift by the mean eigenvalue q and scale by p so that B = (A - qI)/p has eigenvalues
    // 2 cos(phi + 2 pi k / 3), with cos(3 phi) = det(B) / 2 and phi in [0, pi/3].
    const double q = (a00 + a11 + a22) / 3.0;
    const double d0 = a00 - q;
    const double d1 = a11 - q;
    const double d2 = a22 - q;
    const double p2 = (d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * off_diagonal) / 6.0;
    const double p = std::sqrt(p2);
    const double det_shifted =
        d0 * (d1 * d2 - a12 * a12) - a01 * (a01 * d2 - a12 * a02) + a02 * (a01 * a12 - d1 * a02);
    const double denominator = 2.0 * p2 * p;  // 0 only for A = qI, where det_shifted is 0 too
    double half_det = det_shifted / (denominator > 1e-300 ? denominator : 1e-300);
    half_det = half_det > 1.0 ? 1.0 : half_det;
    half_det = half_det < -1.0 ? -1.0 : half_det;
    // With t = phi - pi/6 in [-pi/6, pi/6]: cos(phi) and sin(phi) from cos(t) and sin(t).
    const double t = AcosApprox(half_det) / 3.0 - std::numbers::pi / 6.0;
    double cos_t = 0.0;
    double sin_t = 0.0;
    CosSinSmall(t, cos_t, sin_t);
    constexpr double kHalfSqrt3 = 0.8660254037844386;
    const double cos_phi = kHalfSqrt3 * cos_t - 0.5 * sin_t;
    const double sin_phi = 0.5 * cos_t + kHalfSqrt3 * sin_t;
    const double l1 = q + 2.0 * p * cos_phi;
    const double l3 = q - p * (cos_phi + std::numbers::sqrt3 * sin_phi);  // 2p cos(phi + 2pi/3)
    const double l2 = 3.0 * q - l1 - l3;
    // A diagonal matrix gets its sorted diagonal exactly, which the formula would round.
    const double high01 = a00 > a11 ? a00 : a11;
    const double low01 = a00 > a11 ? a11 : a00;
    const double max_diagonal = high01 > a22 ? high01 : a22;
    const double min_diagonal = low01 < a22 ? low01 : a22;
    const double high01_or_a22 = high01 < a22 ? high01 : a22;
    const double mid_diagonal = low01 > high01_or_a22 ? low01 : high01_or_a22;
    const bool diagonal = off_diagonal == 0.0;
    return {diagonal ? max_diagonal : l1, diagonal ? mid_diagonal : l2,
            diagonal ? min_diagonal : l3};
}

}  // namespace detail

/// Eigenvalues of a symmetric 3x3 matrix in descending order (l1 >= l2 >= l3), by the closed
/// trigonometric form of the characteristic cubic (Smith 1961) with polynomial acos, cos and sin:
/// no library call and no branch, the hot loop of the NDT descriptor. Absolute error below
/// 1e-8 * |l1| (tested against Eigen's iterative solver): ratios compared with t_e ~ 0.1 come out
/// the same as exact ones unless they lie within ~1e-7 of the threshold. Exact for diagonal
/// input. Only the upper triangle is read.
inline Eigen::Vector3d SymmetricEigenvaluesDescending(const Eigen::Matrix3d& a) {
    const detail::Eigenvalues3 e =
        detail::SymmetricEigenvalues(a(0, 0), a(0, 1), a(0, 2), a(1, 1), a(1, 2), a(2, 2));
    return {e.l1, e.l2, e.l3};
}

/// A unit eigenvector of the symmetric matrix `a` for its eigenvalue `lambda`, from the largest
/// cross product of two rows of (a - lambda I). Accurate when lambda is well separated from the
/// other eigenvalues (for NDT shapes the separation is at least 1/t_e); for a repeated
/// eigenvalue it returns some unit vector of the eigenspace, computed by Eigen's solver. Only
/// the upper triangle is read.
Eigen::Vector3d SymmetricEigenvector(const Eigen::Matrix3d& a, double lambda);

}  // namespace lidarloop::core

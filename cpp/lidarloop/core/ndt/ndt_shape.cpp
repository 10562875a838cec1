// Compiled with -fno-math-errno -fno-trapping-math (see CMakeLists.txt): without them GCC keeps
// the branches of the selects and square roots below and does not vectorise the batch loop.
// Neither flag changes a result: this code reads neither errno nor floating-point exceptions.
#include "lidarloop/core/ndt/ndt_shape.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>

#include "lidarloop/core/detail/vector_clones.hpp"
#include "lidarloop/core/eigen3x3.hpp"

namespace lidarloop::core {
namespace {

// One classified covariance. Every field is a double, even the codes: GCC 12 does not vectorise
// the batch loop when it also stores narrower types.
struct ShapeResult {
    double shape_code;  // static_cast<double>(CellShape)
    double l2_over_l1;
    double axis_x, axis_y, axis_z;
    double needs_solver;  // 1: planar or linear, but the eigenvector's eigenvalue is repeated

    CellShape shape() const { return static_cast<CellShape>(static_cast<int>(shape_code)); }
};

constexpr double Code(CellShape shape) { return static_cast<double>(static_cast<int>(shape)); }

constexpr double Select(bool condition, double a, double b) { return condition ? a : b; }

// The cross product of two rows of (A - lambda I) with the largest norm seen so far: rows 0 x 1,
// then 0 x 2, then 1 x 2; a later one replaces it only when strictly larger.
struct CrossProduct {
    double x, y, z;
    double norm2 = x * x + y * y + z * z;

    LIDARLOOP_ALWAYS_INLINE void KeepLarger(const CrossProduct& other) {
        const bool larger = other.norm2 > norm2;
        x = Select(larger, other.x, x);
        y = Select(larger, other.y, y);
        z = Select(larger, other.z, z);
        norm2 = Select(larger, other.norm2, norm2);
    }
};

// Every branch is a select on one comparison of doubles (GCC 12 does not vectorise selects on
// combined bools), so the caller's loop vectorises; it must be inlined there (into each target
// clone) for that. Ratios of a rejected test are set to 2, above any t_e in (0, 1).
LIDARLOOP_ALWAYS_INLINE ShapeResult ClassifyUpperTriangle(double a00, double a01, double a02,
                                                          double a11, double a12, double a22,
                                                          double t_e) {
    // x - x is 0 for finite x and NaN for NaN and +-Inf; a non-finite matrix is replaced by 0,
    // which has no spread and so comes out degenerate.
    const double finite_probe =
        (a00 - a00) + (a01 - a01) + (a02 - a02) + (a11 - a11) + (a12 - a12) + (a22 - a22);
    const bool finite = finite_probe == 0.0;
    a00 = Select(finite, a00, 0.0);
    a01 = Select(finite, a01, 0.0);
    a02 = Select(finite, a02, 0.0);
    a11 = Select(finite, a11, 0.0);
    a12 = Select(finite, a12, 0.0);
    a22 = Select(finite, a22, 0.0);
    const detail::Eigenvalues3 e = detail::SymmetricEigenvalues(a00, a01, a02, a11, a12, a22);
    const double l1 = Select(e.l1 > 0.0, e.l1, 0.0);
    const double l2 = Select(e.l2 > 0.0, e.l2, 0.0);
    const double l3 = Select(e.l3 > 0.0, e.l3, 0.0);
    // No spread (all points equal, or not finite): l1 ~ 0 relative to the matrix's size.
    const double trace = a00 + a11 + a22;
    const double min_spread = 1e-12 * Select(trace > 1.0, trace, 1.0);
    const bool spread = l1 > min_spread;
    const double l2_over_l1 = Select(spread, l2 / Select(spread, l1, 1.0), 0.0);
    const double linear_ratio = Select(spread, l2_over_l1, 2.0);
    double planar_ratio = l3 / Select(l2 > 0.0, l2, 1.0);
    planar_ratio = Select(spread, planar_ratio, 2.0);
    planar_ratio = Select(linear_ratio < t_e, 2.0, planar_ratio);  // linear wins
    double shape_code = Code(CellShape::kDegenerate);
    shape_code = Select(spread, Code(CellShape::kSpherical), shape_code);
    shape_code = Select(planar_ratio < t_e, Code(CellShape::kPlanar), shape_code);
    shape_code = Select(linear_ratio < t_e, Code(CellShape::kLinear), shape_code);
    const double oriented_ratio = Select(linear_ratio < planar_ratio, linear_ratio, planar_ratio);
    const bool oriented = oriented_ratio < t_e;  // planar or linear
    // The axis: e1 of a line, e3 (the normal) of a plane, orthogonal to every row of
    // (A - lambda I); the largest cross product of two rows has the least cancellation.
    const double lambda = Select(linear_ratio < t_e, l1, l3);
    const double r00 = a00 - lambda;
    const double r11 = a11 - lambda;
    const double r22 = a22 - lambda;
    CrossProduct best{a01 * a12 - a02 * r11, a02 * a01 - r00 * a12, r00 * r11 - a01 * a01};
    best.KeepLarger({a01 * r22 - a02 * a12, a02 * a02 - r00 * r22, r00 * a12 - a01 * a02});
    best.KeepLarger({r11 * r22 - a12 * a12, a12 * a02 - a01 * r22, a01 * a12 - r11 * a02});
    const double ax = best.x;
    const double ay = best.y;
    const double az = best.z;
    const double best_norm2 = best.norm2;
    const double scale = std::abs(r00) + std::abs(r11) + std::abs(r22) + std::abs(a01) +
                         std::abs(a02) + std::abs(a12);
    const double scale2 = scale * scale;
    const bool independent_rows = best_norm2 > 1e-20 * scale2 * scale2;
    const double inverse_norm = 1.0 / std::sqrt(Select(independent_rows, best_norm2, 1.0));
    ShapeResult r;
    r.shape_code = shape_code;
    r.l2_over_l1 = l2_over_l1;
    r.axis_x = Select(oriented, Select(independent_rows, ax * inverse_norm, 0.0), 0.0);
    r.axis_y = Select(oriented, Select(independent_rows, ay * inverse_norm, 0.0), 0.0);
    r.axis_z = Select(oriented, Select(independent_rows, az * inverse_norm, 1.0), 1.0);
    r.needs_solver = Select(oriented, Select(independent_rows, 0.0, 1.0), 0.0);
    return r;
}

// Repeated eigenvalue: (A - lambda I) has rank < 2 and any vector of its kernel will do; rare
// enough (exactly symmetric input) for Eigen's iterative solver.
Eigen::Vector3d AxisBySolver(const Eigen::Matrix3d& upper, CellShape shape) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(
        Eigen::Matrix3d(upper.selfadjointView<Eigen::Upper>()));
    return solver.eigenvectors().col(shape == CellShape::kLinear ? 2 : 0);
}

LIDARLOOP_VECTOR_CLONES
void ClassifyBatch(std::size_t n, const double* __restrict xx, const double* __restrict xy,
                   const double* __restrict xz, const double* __restrict yy,
                   const double* __restrict yz, const double* __restrict zz, double t_e,
                   double* __restrict shape_code, double* __restrict ratio,
                   double* __restrict axis_x, double* __restrict axis_y, double* __restrict axis_z,
                   double* __restrict needs_solver) {
    for (std::size_t i = 0; i < n; ++i) {
        const ShapeResult r = ClassifyUpperTriangle(xx[i], xy[i], xz[i], yy[i], yz[i], zz[i], t_e);
        shape_code[i] = r.shape_code;
        ratio[i] = r.l2_over_l1;
        axis_x[i] = r.axis_x;
        axis_y[i] = r.axis_y;
        axis_z[i] = r.axis_z;
        needs_solver[i] = r.needs_solver;
    }
}

}  // namespace

CellShapeInfo ClassifyCovariance(const Eigen::Matrix3d& covariance_m2, double t_e) {
    const Eigen::Matrix3d& a = covariance_m2;
    const ShapeResult r =
        ClassifyUpperTriangle(a(0, 0), a(0, 1), a(0, 2), a(1, 1), a(1, 2), a(2, 2), t_e);
    CellShapeInfo info;
    info.shape = r.shape();
    info.l2_over_l1 = r.l2_over_l1;
    info.axis = r.needs_solver != 0.0 ? AxisBySolver(a, info.shape)
                                      : Eigen::Vector3d(r.axis_x, r.axis_y, r.axis_z);
    return info;
}

void ClassifyCells(const NdtCellColumns& cells, double t_e, CellShapeColumns& shapes) {
    const std::size_t n = cells.size();
    shapes.shape.resize(n);
    shapes.l2_over_l1.resize(n);
    shapes.axis_x.resize(n);
    shapes.axis_y.resize(n);
    shapes.axis_z.resize(n);
    thread_local std::vector<double> shape_code;
    thread_local std::vector<double> needs_solver;
    shape_code.resize(n);
    needs_solver.resize(n);
    ClassifyBatch(n, cells.cov_xx_m2.data(), cells.cov_xy_m2.data(), cells.cov_xz_m2.data(),
                  cells.cov_yy_m2.data(), cells.cov_yz_m2.data(), cells.cov_zz_m2.data(), t_e,
                  shape_code.data(), shapes.l2_over_l1.data(), shapes.axis_x.data(),
                  shapes.axis_y.data(), shapes.axis_z.data(), needs_solver.data());
    for (std::size_t i = 0; i < n; ++i) {
        shapes.shape[i] = static_cast<CellShape>(static_cast<int>(shape_code[i]));
        if (needs_solver[i] == 0.0) continue;
        const Eigen::Vector3d axis = AxisBySolver(cells.Cell(i).covariance_m2, shapes.shape[i]);
        shapes.axis_x[i] = axis.x();
        shapes.axis_y[i] = axis.y();
        shapes.axis_z[i] = axis.z();
    }
}

}  // namespace lidarloop::core

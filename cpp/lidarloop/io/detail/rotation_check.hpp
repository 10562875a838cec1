#pragma once

// Internal helper shared by the pose readers (KITTI poses and calibration, 3DTK .frames). Not
// installed as public API promise.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lidarloop/io/detail/text_parsing.hpp"

namespace lidarloop::io::detail {

/// The rotation nearest to `m`, the 3x3 part of a pose matrix read on the current line of
/// `reader`. Files print rotations with 6 (3DTK) or 7 (KITTI) digits: small deviations are
/// accepted and snapped to the nearest rotation (so that inverses by transposition stay exact);
/// what is no rotation at all (scaled, mirrored, garbage: max |R^T R - I| > 1e-3 or det <= 0)
/// fails naming the line.
inline Eigen::Matrix3d NearestRotationOrFail(const LineReader& reader, const Eigen::Matrix3d& m) {
    const double error = (m.transpose() * m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (error > 1e-3 || m.determinant() <= 0.0) {
        reader.Fail("the 3x3 part is not a rotation (max |R^T R - I| = " + ShortNumber(error) +
                    ", det = " + ShortNumber(m.determinant()) + ")");
    }
    return Eigen::Quaterniond(m).normalized().toRotationMatrix();
}

}  // namespace lidarloop::io::detail

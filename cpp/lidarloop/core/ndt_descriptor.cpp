#include "lidarloop/core/ndt_descriptor.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "lidarloop/core/eigen3x3.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/sphere_partition.hpp"

namespace lidarloop::core {
namespace {

// A classified cell, independent of any rotation: its shape, orientation axis and the row and
// column parts of its feature index that rotation cannot change.
struct ClassifiedCell {
    CellShape shape;
    Eigen::Vector3d axis;
    Eigen::Vector3d mean_m;
    int row;               // range interval
    int spherical_column;  // for spherical cells
};

// A line has two unit vectors, and the rotation that aligns one of them differs from the one
// aligning the other by a half turn, which moves cells to other orientation classes (the
// partition is not symmetric under it). Each line is therefore given the sign that points
// against the centroid of the cell means, a choice that turns with the scan; when the line is
// too close to perpendicular to the centroid for the sign to be stable, both signs are kept.
constexpr double kSignAmbiguity = 0.1;  // |cos| of the angle between line and centroid

// The orientation partitions of the planar and linear classes (absent when a count is 0).
struct Partitions {
    std::optional<HalfSpherePartition> planar;
    std::optional<HalfSpherePartition> linear;
};

int RangeRow(const Eigen::Vector3d& mean_m, const std::vector<double>& limits_m) {
    const double range_m = mean_m.norm();
    return static_cast<int>(std::upper_bound(limits_m.begin(), limits_m.end(), range_m) -
                            limits_m.begin());
}

int SphericalColumn(double l2_over_l1, const NdtConfig& config) {
    // s equal sub-intervals of [t_e, 1], the values l2/l1 a spherical cell can have.
    const double t =
        (l2_over_l1 - config.eigen_ratio_threshold) / (1.0 - config.eigen_ratio_threshold);
    const int s = config.spherical_classes;
    return std::clamp(static_cast<int>(t * s), 0, s - 1);
}

std::vector<ClassifiedCell> ClassifyCells(const std::vector<NdtCell>& cells,
                                          const NdtConfig& config, std::size_t& degenerate) {
    std::vector<ClassifiedCell> classified;
    classified.reserve(cells.size());
    for (const NdtCell& cell : cells) {
        const CellShapeInfo info =
            ClassifyCovariance(cell.covariance_m2, config.eigen_ratio_threshold);
        if (info.shape == CellShape::kDegenerate) {
            ++degenerate;
            continue;
        }
        const int spherical_column =
            config.spherical_classes > 0 ? SphericalColumn(info.l2_over_l1, config) : 0;
        classified.push_back({info.shape, info.axis, cell.mean_m,
                              RangeRow(cell.mean_m, config.range_limits_m), spherical_column});
    }
    return classified;
}

// Nearest-line classification (eq. 2) of many axes seen after rotating the scan by R. Because
// (R a) . c_j = a . (R^T c_j), the few centres are rotated once instead of every cell's axis.
class RotatedLines {
public:
    RotatedLines(const std::optional<HalfSpherePartition>& partition, const Eigen::Matrix3d& R) {
        if (!partition) return;
        for (const Eigen::Vector3d& centre : partition->centres()) {
            const Eigen::Vector3d c = R.transpose() * centre;
            x_.push_back(c.x());
            y_.push_back(c.y());
            z_.push_back(c.z());
        }
    }
    bool empty() const { return x_.empty(); }
    int Classify(const Eigen::Vector3d& axis) const {
        int best = 0;
        double best_dot = -1.0;
        for (std::size_t j = 0; j < x_.size(); ++j) {
            const double dot = std::abs(axis.x() * x_[j] + axis.y() * y_[j] + axis.z() * z_[j]);
            if (dot > best_dot) {  // strict: ties keep the lowest index, as NearestLine does
                best_dot = dot;
                best = static_cast<int>(j);
            }
        }
        return best;
    }

private:
    std::vector<double> x_, y_, z_;
};

// Feature column of a cell (eq. 1 and 2); -1 when its class is not counted (s, p or l is 0).
int FeatureColumn(const ClassifiedCell& cell, const NdtConfig& config, const RotatedLines& planes,
                  const RotatedLines& lines) {
    switch (cell.shape) {
        case CellShape::kSpherical:
            return config.spherical_classes > 0 ? cell.spherical_column : -1;
        case CellShape::kPlanar:
            if (planes.empty()) return -1;
            return config.spherical_classes + planes.Classify(cell.axis);
        case CellShape::kLinear:
            if (lines.empty()) return -1;
            return config.spherical_classes + config.planar_classes + lines.Classify(cell.axis);
        case CellShape::kDegenerate:
            break;
    }
    return -1;
}

NdtDescriptor CountFeatures(const std::vector<ClassifiedCell>& cells, const Eigen::Matrix3d& R,
                            const NdtConfig& config, const Partitions& partitions) {
    NdtDescriptor f;
    f.rows = config.RangeCount();
    f.cols = config.FeatureCount();
    f.counts.assign(static_cast<std::size_t>(f.rows * f.cols), 0.0f);
    f.R_aligned_sensor = R;
    const RotatedLines planes(partitions.planar, R);
    const RotatedLines lines(partitions.linear, R);
    for (const ClassifiedCell& cell : cells) {
        const int column = FeatureColumn(cell, config, planes, lines);
        if (column < 0) continue;
        f.counts[static_cast<std::size_t>(cell.row * f.cols + column)] += 1.0f;
        f.total += 1.0;
    }
    f.normalised.resize(f.counts.size());
    const double inverse_total = f.total > 0.0 ? 1.0 / f.total : 0.0;
    for (std::size_t i = 0; i < f.counts.size(); ++i) {
        f.normalised[i] = static_cast<float>(f.counts[i] * inverse_total);
    }
    return f;
}

// Z and Y of eq. (4)-(7) over a histogram of line directions. Y needs a non-zero second peak:
// with only zeros left, "p_i >= t_a * 0" would make every empty class ambiguous.
void AmbiguousPeaks(const std::vector<double>& histogram, double t_a, std::vector<int>& z,
                    std::vector<int>& y) {
    z.clear();
    y.clear();
    const double first = *std::max_element(histogram.begin(), histogram.end());
    if (first <= 0.0) return;
    for (int i = 0; i < static_cast<int>(histogram.size()); ++i) {
        if (histogram[i] >= t_a * first) z.push_back(i);
    }
    double second = 0.0;
    for (int i = 0; i < static_cast<int>(histogram.size()); ++i) {
        if (std::find(z.begin(), z.end(), i) == z.end()) second = std::max(second, histogram[i]);
    }
    if (second <= 0.0) return;
    for (int i = 0; i < static_cast<int>(histogram.size()); ++i) {
        if (std::find(z.begin(), z.end(), i) == z.end() && histogram[i] >= t_a * second) {
            y.push_back(i);
        }
    }
}

// R_z of section II-C: turns the line P onto the z axis.
Eigen::Matrix3d AlignToZ(const Eigen::Vector3d& line) {
    return Eigen::Quaterniond::FromTwoVectors(line, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// R_y of section II-C: a rotation about z that brings `v` (already rotated by R_z) into the
// yz plane, on the +y side. nullopt when v is (nearly) the z axis and sets no direction.
std::optional<Eigen::Matrix3d> AlignToYz(const Eigen::Vector3d& v) {
    if (std::hypot(v.x(), v.y()) < 1e-9) return std::nullopt;
    return Eigen::AngleAxisd(std::atan2(v.x(), v.y()), Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// The orientation classes of the planar (or linear) cells: how many cells each holds, and the
// direction a peak in it stands for: the principal axis of its cells' axes (their mean line) or,
// as the paper writes, the class's partition line P_i.
struct LineClasses {
    std::vector<double> counts;
    std::vector<Eigen::Vector3d> directions;
};

LineClasses SummariseLines(const std::vector<ClassifiedCell>& cells, CellShape shape,
                           const HalfSpherePartition& partition, bool mean_direction) {
    const auto n = static_cast<std::size_t>(partition.size());
    LineClasses classes{std::vector<double>(n, 0.0), partition.centres()};
    std::vector<Eigen::Matrix3d> scatter(n, Eigen::Matrix3d::Zero());
    for (const ClassifiedCell& cell : cells) {
        if (cell.shape != shape) continue;
        const auto j = static_cast<std::size_t>(partition.NearestLine(cell.axis));
        classes.counts[j] += 1.0;
        scatter[j].noalias() += cell.axis * cell.axis.transpose();
    }
    if (!mean_direction) return classes;
    for (std::size_t j = 0; j < n; ++j) {
        if (classes.counts[j] <= 0.0) continue;
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
        solver.computeDirect(scatter[j]);
        classes.directions[j] = solver.eigenvectors().col(2).normalized();
    }
    return classes;
}

Eigen::Vector3d CentroidDirection(const std::vector<ClassifiedCell>& cells) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const ClassifiedCell& cell : cells) sum += cell.mean_m;
    const double norm = sum.norm();
    return norm > 0.0 ? Eigen::Vector3d(sum / norm) : Eigen::Vector3d::Zero();
}

// The signed unit vectors of `line` to align: the one pointing against `centroid`, or both.
std::vector<Eigen::Vector3d> SignedVariants(const Eigen::Vector3d& line,
                                            const Eigen::Vector3d& centroid) {
    const double cosine = line.dot(centroid);
    if (std::abs(cosine) < kSignAmbiguity) return {line, -line};
    return {cosine > 0.0 ? Eigen::Vector3d(-line) : line};
}

// The rotations R_y R_z of section II-C, one per combination of an entry of Z with another
// entry of Z or Y; R_z alone when no second direction exists; identity without planar cells.
std::vector<Eigen::Matrix3d> CandidateRotations(const std::vector<ClassifiedCell>& cells,
                                                const NdtConfig& config,
                                                const Partitions& partitions) {
    if (!config.normalise_rotation || !partitions.planar) return {Eigen::Matrix3d::Identity()};
    const bool mean = config.align_to_mean_direction;
    const LineClasses planes = SummariseLines(cells, CellShape::kPlanar, *partitions.planar, mean);
    std::vector<int> z;
    std::vector<int> y;
    AmbiguousPeaks(planes.counts, config.ambiguity_ratio, z, y);
    if (z.empty()) return {Eigen::Matrix3d::Identity()};
    // Second directions: the other planar peaks; else, as the paper allows, linear peaks.
    std::vector<Eigen::Vector3d> seconds;
    for (int j : y) seconds.push_back(planes.directions[j]);
    if (z.size() + y.size() < 2 && partitions.linear && partitions.linear->size() > 1) {
        const LineClasses lines =
            SummariseLines(cells, CellShape::kLinear, *partitions.linear, mean);
        std::vector<int> lz;
        std::vector<int> ly;
        AmbiguousPeaks(lines.counts, config.ambiguity_ratio, lz, ly);
        for (int j : lz) seconds.push_back(lines.directions[j]);
    }
    const Eigen::Vector3d centroid = CentroidDirection(cells);
    std::vector<Eigen::Matrix3d> rotations;
    for (int i : z) {
        for (const Eigen::Vector3d& first : SignedVariants(planes.directions[i], centroid)) {
            const Eigen::Matrix3d R_z = AlignToZ(first);
            std::size_t added = 0;
            const auto add_second = [&](const Eigen::Vector3d& line) {
                for (const Eigen::Vector3d& second : SignedVariants(line, centroid)) {
                    if (const auto R_y = AlignToYz(R_z * second)) {
                        rotations.push_back(*R_y * R_z);
                        ++added;
                    }
                }
            };
            for (int j : z) {
                if (j != i) add_second(planes.directions[j]);
            }
            for (const Eigen::Vector3d& second : seconds) add_second(second);
            if (added == 0) rotations.push_back(R_z);
        }
    }
    return rotations;
}

Partitions MakePartitions(const NdtConfig& config) {
    Partitions partitions;
    if (config.planar_classes > 0) partitions.planar.emplace(config.planar_classes);
    if (config.linear_classes > 0) partitions.linear.emplace(config.linear_classes);
    return partitions;
}

PointCloud Rotated(const PointCloud& cloud, const Eigen::Matrix3d& R) {
    const Eigen::Matrix3f Rf = R.cast<float>();
    PointCloud rotated(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) rotated[i] = Rf * cloud[i];
    return rotated;
}

}  // namespace

CellShapeInfo ClassifyCovariance(const Eigen::Matrix3d& covariance_m2, double t_e) {
    CellShapeInfo info;
    if (!covariance_m2.allFinite()) return info;
    // Eigenvalues first; only the one eigenvector the shape needs is computed (the hot loop).
    const Eigen::Vector3d lambda = SymmetricEigenvaluesDescending(covariance_m2).cwiseMax(0.0);
    const double l1 = lambda[0];
    const double l2 = lambda[1];
    const double l3 = lambda[2];
    if (!(l1 > 1e-12 * std::max(1.0, covariance_m2.trace()))) return info;  // no spread
    info.l2_over_l1 = l2 / l1;
    if (l2 / l1 < t_e) {
        info.shape = CellShape::kLinear;
        info.axis = SymmetricEigenvector(covariance_m2, lambda[0]);
    } else if (l3 / l2 < t_e) {
        info.shape = CellShape::kPlanar;
        info.axis = SymmetricEigenvector(covariance_m2, lambda[2]);
    } else {
        info.shape = CellShape::kSpherical;
    }
    return info;
}

NdtDescriptorSet ComputeNdtDescriptorSet(const PointCloud& cloud, const NdtConfig& config) {
    config.Validate();
    NdtDescriptorSet set;
    const Partitions partitions = MakePartitions(config);
    const auto cells_of = [&](const PointCloud& points) {
        return ClassifyCells(ComputeNdtCells(points, config.cell_size_m, config.min_points_per_cell,
                                             &set.cell_stats),
                             config, set.degenerate_cells);
    };
    const std::vector<ClassifiedCell> cells = cells_of(cloud);
    for (const Eigen::Matrix3d& R : CandidateRotations(cells, config, partitions)) {
        if (config.regrid_rotations && !R.isIdentity()) {
            NdtDescriptor f = CountFeatures(cells_of(Rotated(cloud, R)),
                                            Eigen::Matrix3d::Identity(), config, partitions);
            f.R_aligned_sensor = R;
            set.descriptors.push_back(std::move(f));
        } else {
            set.descriptors.push_back(CountFeatures(cells, R, config, partitions));
        }
    }
    if (set.descriptors.front().total <= 0.0) {
        throw EmptyInputError(
            "no NDT cell could be classified (" + std::to_string(set.cell_stats.points_used) +
            " usable points, " + std::to_string(set.cell_stats.sparse_cells) +
            " cells with fewer than " + std::to_string(config.min_points_per_cell) + " points)");
    }
    return set;
}

double NdtDifference(const NdtDescriptor& f, const NdtDescriptor& g) {
    if (f.rows != g.rows || f.cols != g.cols || f.normalised.size() != g.normalised.size()) {
        throw ConfigError("NDT descriptors of different shapes cannot be compared");
    }
    double sum = 0.0;
    for (int row = 0; row < f.rows; ++row) {
        float squared = 0.0f;
        const std::size_t begin = static_cast<std::size_t>(row * f.cols);
        for (std::size_t k = begin; k < begin + static_cast<std::size_t>(f.cols); ++k) {
            const float d = f.normalised[k] - g.normalised[k];
            squared += d * d;
        }
        sum += std::sqrt(static_cast<double>(squared));
    }
    const double larger = std::max(f.total, g.total);
    const double smaller = std::min(f.total, g.total);
    return smaller > 0.0 ? sum * larger / smaller : std::numeric_limits<double>::infinity();
}

double NdtSetDifference(const NdtDescriptorSet& f, const NdtDescriptorSet& g) {
    double best = std::numeric_limits<double>::infinity();
    for (const NdtDescriptor& a : f.descriptors) {
        for (const NdtDescriptor& b : g.descriptors) best = std::min(best, NdtDifference(a, b));
    }
    return best;
}

}  // namespace lidarloop::core

#include "lidarloop/registration/compact_prepared_scan.hpp"

#include <algorithm>
#include <cmath>

namespace lidarloop::registration {
namespace {

constexpr float kLevels = 32767.0F;

std::int16_t Quantise(float value, float step) {
    return static_cast<std::int16_t>(std::clamp(std::lround(value / step), -32767L, 32767L));
}

float Sign(float value) { return value < 0.0F ? -1.0F : 1.0F; }

}  // namespace

void EncodeNormal(const Eigen::Vector3f& normal, std::int16_t& u, std::int16_t& v) {
    // Project onto the octahedron |x| + |y| + |z| = 1, then fold the lower half over the upper.
    const float l1 = normal.cwiseAbs().sum();
    float x = l1 > 0.0F ? normal.x() / l1 : 0.0F;
    float y = l1 > 0.0F ? normal.y() / l1 : 0.0F;
    if (normal.z() < 0.0F) {
        const float folded_x = (1.0F - std::abs(y)) * Sign(x);
        y = (1.0F - std::abs(x)) * Sign(y);
        x = folded_x;
    }
    u = Quantise(x, 1.0F / kLevels);
    v = Quantise(y, 1.0F / kLevels);
}

Eigen::Vector3f DecodeNormal(std::int16_t u, std::int16_t v) {
    float x = static_cast<float>(u) / kLevels;
    float y = static_cast<float>(v) / kLevels;
    const float z = 1.0F - std::abs(x) - std::abs(y);
    if (z < 0.0F) {
        const float unfolded_x = (1.0F - std::abs(y)) * Sign(x);
        y = (1.0F - std::abs(x)) * Sign(y);
        x = unfolded_x;
    }
    return Eigen::Vector3f(x, y, z).normalized();
}

CompactPreparedScan::Surface CompactPreparedScan::Encode(const SurfacePoints& points) {
    Surface surface;
    float farthest_m = 0.0F;
    for (const auto& point : points.points())
        farthest_m = std::max(farthest_m, point.cwiseAbs().maxCoeff());
    surface.step_m = farthest_m > 0.0F ? farthest_m / kLevels : 1.0F;
    surface.position.reserve(3 * points.size());
    surface.normal.reserve(2 * points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
        for (int axis = 0; axis < 3; ++axis)
            surface.position.push_back(Quantise(points.points()[i][axis], surface.step_m));
        std::int16_t u = 0, v = 0;
        EncodeNormal(points.normals()[i], u, v);
        surface.normal.push_back(u);
        surface.normal.push_back(v);
    }
    return surface;
}

std::vector<Eigen::Vector3f> CompactPreparedScan::Positions(const Surface& surface) {
    std::vector<Eigen::Vector3f> points(surface.size());
    for (std::size_t i = 0; i < surface.size(); ++i) {
        points[i] = Eigen::Vector3f(surface.position[3 * i], surface.position[3 * i + 1],
                                    surface.position[3 * i + 2]) *
                    surface.step_m;
    }
    return points;
}

std::shared_ptr<const SurfacePoints> CompactPreparedScan::Decode(const Surface& surface) {
    std::vector<Eigen::Vector3f> normals(surface.size());
    for (std::size_t i = 0; i < surface.size(); ++i)
        normals[i] = DecodeNormal(surface.normal[2 * i], surface.normal[2 * i + 1]);
    return std::make_shared<const SurfacePoints>(Positions(surface), std::move(normals));
}

CompactPreparedScan::CompactPreparedScan(const PreparedScan& scan)
    : prepared_(scan.structure != nullptr),
      distinctive_count_(scan.structure_distinctive.size()),
      input_points_(scan.input_points),
      usable_points_(scan.usable_points),
      structure_roughness_m_(scan.structure_roughness_m),
      view_centre_(scan.view_centre) {
    if (scan.structure) {
        structure_ = Encode(*scan.structure);
        // From the points as stored, as verification sees them: a map saved and loaded again
        // has the same layouts.
        layout_ = ComputeLayoutSignature(Positions(structure_));
    }
    if (scan.ground) ground_ = Encode(*scan.ground);
    distinctive_bits_.assign((scan.structure_distinctive.size() + 7) / 8, 0);
    for (std::size_t i = 0; i < scan.structure_distinctive.size(); ++i) {
        if (scan.structure_distinctive[i] != 0)
            distinctive_bits_[i / 8] =
                static_cast<std::uint8_t>(distinctive_bits_[i / 8] | (1U << (i % 8)));
    }
}

PreparedScan CompactPreparedScan::Expand() const {
    PreparedScan scan;
    scan.input_points = input_points_;
    scan.usable_points = usable_points_;
    scan.structure_roughness_m = structure_roughness_m_;
    scan.view_centre = view_centre_;
    if (!prepared_) return scan;
    scan.structure = Decode(structure_);
    scan.ground = Decode(ground_);
    scan.structure_distinctive.resize(distinctive_count_);
    for (std::size_t i = 0; i < distinctive_count_; ++i)
        scan.structure_distinctive[i] = (distinctive_bits_[i / 8] >> (i % 8)) & 1U;
    return scan;
}

std::size_t CompactPreparedScan::MemoryBytes() const {
    const auto bytes = [](const Surface& surface) {
        return (surface.position.capacity() + surface.normal.capacity()) * sizeof(std::int16_t);
    };
    return bytes(structure_) + bytes(ground_) + distinctive_bits_.capacity() +
           layout_.values.capacity() * sizeof(float);
}

}  // namespace lidarloop::registration

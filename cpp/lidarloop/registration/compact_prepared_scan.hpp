#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "lidarloop/registration/layout_signature.hpp"
#include "lidarloop/registration/prepared_scan.hpp"

namespace lidarloop::registration {

/// A PreparedScan as kept for a whole run: about 10 bytes per point instead of about 40, so that
/// an hour of scans at 10 Hz fits in memory. Positions are 16-bit integers in steps of the
/// farthest coordinate / 32767 (1.8 mm at 60 m; at most half a step off), normals are
/// octahedral-encoded in two 16-bit integers (about 1e-4 rad off), distinctive flags are bits,
/// and there are no search trees: Expand() rebuilds them when the scan is verified.
class CompactPreparedScan {
public:
    /// An empty scan (e.g. a skipped one): Expand() gives a PreparedScan without points.
    CompactPreparedScan() = default;
    explicit CompactPreparedScan(const PreparedScan& scan);

    /// The scan ready to verify: points and normals decoded, trees built (thread-safe).
    PreparedScan Expand() const;
    /// Whether the scan was prepared (an empty PreparedScan has no structure).
    bool prepared() const { return prepared_; }
    /// PreparedScan::view_centre, kept as it was (NaN for an empty scan).
    const Eigen::Vector3d& view_centre() const { return view_centre_; }
    /// The layout of its structure (ComputeLayoutSignature of the stored, encoded points); empty
    /// for an empty scan.
    const LayoutSignature& layout() const { return layout_; }
    /// Heap bytes held (the figure bench and LoopDetector::prepared_bytes report).
    std::size_t MemoryBytes() const;

private:
    // One surface class: points and normals, encoded.
    struct Surface {
        float step_m = 0.0F;                 // position quantum
        std::vector<std::int16_t> position;  // x, y, z per point, in steps
        std::vector<std::int16_t> normal;    // octahedral u, v per point
        std::size_t size() const { return position.size() / 3; }
    };
    static Surface Encode(const SurfacePoints& points);
    static std::vector<Eigen::Vector3f> Positions(const Surface& surface);
    static std::shared_ptr<const SurfacePoints> Decode(const Surface& surface);

    bool prepared_ = false;
    Surface structure_;
    Surface ground_;
    std::vector<std::uint8_t> distinctive_bits_;  // bit i % 8 of byte i / 8: structure point i
    std::size_t distinctive_count_ = 0;
    std::size_t input_points_ = 0;
    std::size_t usable_points_ = 0;
    double structure_roughness_m_ = 0.0;
    LayoutSignature layout_;
    Eigen::Vector3d view_centre_ =
        Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

/// Octahedral encoding of a unit normal in two integers of [-32767, 32767] and back (the
/// decoded normal has unit length). Exposed for the tests.
void EncodeNormal(const Eigen::Vector3f& normal, std::int16_t& u, std::int16_t& v);
Eigen::Vector3f DecodeNormal(std::int16_t u, std::int16_t v);

}  // namespace lidarloop::registration

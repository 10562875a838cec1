#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace lidarloop::core {

/// Minimum loop size S (Magnusson et al. 2009, II-E): scans this close in the sequence are never
/// loop candidates of each other, since consecutive scans trivially look alike. Counted in scans
/// (the paper: "each scan S_i is compared to all other scans, except for S_{i-S}, ..., S_{i+S}")
/// or in seconds of recording time.
struct MinGap {
    enum class Unit { kScans, kSeconds };

    double value = 30.0;  ///< S; the paper uses 30 scans
    Unit unit = Unit::kScans;

    /// True when scans i and j (recorded at t_i_s, t_j_s) are far enough apart to be compared.
    bool Allows(std::size_t i, std::size_t j, double t_i_s, double t_j_s) const {
        if (unit == Unit::kScans) {
            const double apart = i > j ? static_cast<double>(i - j) : static_cast<double>(j - i);
            return apart > value;
        }
        return (t_i_s > t_j_s ? t_i_s - t_j_s : t_j_s - t_i_s) > value;
    }

    /// Throws ConfigError naming `field` when value is negative or not finite.
    void Validate(const std::string& field) const;
    bool operator==(const MinGap&) const = default;
};

std::string ToString(MinGap::Unit unit);
/// Parses "scans" / "seconds"; throws ConfigError listing the valid names.
MinGap::Unit ParseMinGapUnit(std::string_view name);

}  // namespace lidarloop::core

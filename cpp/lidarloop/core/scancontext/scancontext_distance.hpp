#pragma once

#include <vector>

#include "lidarloop/core/scancontext/scancontext.hpp"

namespace lidarloop::core {

/// A Scan Context made ready for the column-shift distance: every sector column divided by its
/// norm once, so that a comparison is dot products only. Immutable; share freely.
class ScanContextColumns {
public:
    ScanContextColumns() = default;
    /// From the bins of a Scan Context (rings x sectors, ring-major, values >= 0).
    ScanContextColumns(const std::vector<float>& bins, int rings, int sectors);
    explicit ScanContextColumns(const ScanContext& sc)
        : ScanContextColumns(sc.bins, sc.rings, sc.sectors) {}

    int rings() const { return rings_; }
    int sectors() const { return sectors_; }
    /// Columns with a bin that is not 0.
    int occupied_columns() const { return occupied_columns_; }

    /// Unit column values and occupancy (1 or 0) in reversed column order, twice over, one row
    /// per ring and a last row for the occupancy: row[k] belongs to column (sectors - k mod
    /// sectors) mod sectors, for k in [0, 2 sectors). This order makes the values every column
    /// shift meets one contiguous run (see CompareScanContexts).
    const float* ReversedRow(int row) const {
        return reversed_.data() + static_cast<std::ptrdiff_t>(row) * 2 * sectors_;
    }

private:
    int rings_ = 0;
    int sectors_ = 0;
    int occupied_columns_ = 0;
    std::vector<float> reversed_;  // (rings + 1) x 2 sectors
};

/// The Scan Context distance of a query to a candidate and the shift that gives it.
struct ScanContextMatch {
    /// min over shifts n of d(I_q, I_c shifted by n) (Kim & Kim eq. 5, 6): the mean of
    /// 1 - cos(c_j^q, c_{j+n}^c) over the columns j occupied (not all 0) in either; a column
    /// occupied in one only counts as 1 (cos 0), columns empty in both are skipped. In [0, 1]
    /// (the bins are >= 0); 0 for equal descriptors (values below 2e-6, float rounding, read 0);
    /// 1 when no shift overlaps an occupied column of each.
    double distance = 1.0;
    /// n in [0, sectors): query column j is compared with candidate column (j + n) mod sectors.
    int shift = 0;
    /// The yaw that shift implies, of T_candidate_query (query points turned by it land in the
    /// candidate's bins), radians in (-pi, pi].
    double yaw_rad = 0.0;
};

/// The column-shift distance of Kim & Kim (eq. 5, 6) by all N_s shifts; the smallest shift wins a
/// tie. ConfigError when the shapes differ. O(rings x sectors^2), no allocation; thread-safe.
ScanContextMatch CompareScanContexts(const ScanContextColumns& query,
                                     const ScanContextColumns& candidate);

/// CompareScanContexts of two Scan Contexts (prepares both first).
ScanContextMatch CompareScanContexts(const ScanContext& query, const ScanContext& candidate);

}  // namespace lidarloop::core

#pragma once

#include <filesystem>
#include <vector>

#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/prepared_scan.hpp"
#include "lidarloop/registration/verification_config.hpp"

namespace lidarloop::io {

/// The scans of a map reduced for verification (registration::PreparedScan), saved beside its
/// database so that localising against the map can verify its candidates: "LLPS0002", the
/// reduction config as YAML, then per scan whether it is present, its point counts and roughness,
/// and its structure and ground points with normals (float32, sensor frame, metres), and the
/// structure points' distinctive flags. About 24 bytes per kept point. Little-endian binary.
void SavePreparedScans(const std::filesystem::path& file,
                       const std::vector<registration::PreparedScan>& scans,
                       const registration::ScanReductionConfig& reduction);
/// The same for scans kept compact (each expanded while it is written: the file holds the
/// decoded points, one scan in memory at a time).
void SavePreparedScans(const std::filesystem::path& file,
                       const std::vector<registration::CompactPreparedScan>& scans,
                       const registration::ScanReductionConfig& reduction);

/// Prepared scans saved by SavePreparedScans, with the reduction they were made with.
struct StoredPreparedScans {
    std::vector<registration::PreparedScan> scans;
    registration::ScanReductionConfig reduction;
};

/// Loads what SavePreparedScans wrote; ReadError naming what is wrong (magic, config,
/// truncation, absurd counts, non-finite points, trailing bytes).
StoredPreparedScans LoadPreparedScans(const std::filesystem::path& file);

/// Where the prepared scans of the map `database_file` live: the same name with the extension
/// ".scans" (results/database.lldb -> results/database.scans).
std::filesystem::path PreparedScansPathOf(const std::filesystem::path& database_file);

/// Whether `file` begins as a file SavePreparedScans writes (of any version); false when it
/// cannot be read.
bool IsPreparedScansFile(const std::filesystem::path& file);

}  // namespace lidarloop::io

#pragma once

#include <filesystem>

#include "lidarloop/pipeline/descriptor_database.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"

namespace lidarloop::io {

/// Saves a descriptor database (a map to localise against, or a detector's state): "LLDB0001",
/// the configuration as YAML (the descriptor config, so that new scans are described the same
/// way, and `detection`, whose threshold is the default for localising against it), then per
/// scan its time, whether it is valid, and what the method's DescriptorStore::Encode writes (the
/// cumulative histogram row, the NDT descriptor set). Little-endian binary.
void SaveDatabase(const std::filesystem::path& file, const pipeline::DescriptorDatabase& database,
                  const pipeline::DetectorConfig& detection = {});

/// A saved database and the detection config saved with it.
struct StoredDatabase {
    pipeline::DescriptorDatabase database;
    pipeline::DetectorConfig detection;
};

/// Loads a database saved by SaveDatabase with its detection config. A database of lidarloop 0.1
/// kept its threshold in the descriptor section of its method; it comes back as
/// detection.threshold. ReadError as LoadDatabase.
StoredDatabase LoadStoredDatabase(const std::filesystem::path& file);

/// Loads a database saved by SaveDatabase; ReadError naming what is wrong (magic, config,
/// truncation, absurd sizes, trailing bytes).
pipeline::DescriptorDatabase LoadDatabase(const std::filesystem::path& file);

}  // namespace lidarloop::io

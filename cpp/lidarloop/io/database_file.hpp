#pragma once

#include <filesystem>

#include "lidarloop/pipeline/descriptor_database.hpp"

namespace lidarloop::io {

/// Saves a descriptor database (a map to localise against, or a detector's state): "LLDB0001",
/// the descriptor configuration as YAML (so that new scans are described the same way), then per
/// scan its time, whether it is valid, and what the method's DescriptorStore::Encode writes (the
/// cumulative histogram row, the NDT descriptor set). Little-endian binary.
void SaveDatabase(const std::filesystem::path& file, const pipeline::DescriptorDatabase& database);

/// Loads a database saved by SaveDatabase; ReadError naming what is wrong (magic, config,
/// truncation, absurd sizes, trailing bytes).
pipeline::DescriptorDatabase LoadDatabase(const std::filesystem::path& file);

}  // namespace lidarloop::io

#pragma once

#include <filesystem>

namespace lidarloop::io::detail {

/// Checks the record structure of a ROS 1 bag (format 2.0) before rosbag_storage reads it, which
/// trusts every length in the file: a damaged length made it allocate up to 4 GiB, or read past
/// a chunk. Walks the top-level records (each length within the file), and checks that the bag
/// header's index_pos and every chunk info's chunk_pos point at records, that chunks use a known
/// compression and claim at most 1 GiB, and that every index entry points into its chunk (for
/// an uncompressed chunk: at a message record that fits in it). Throws ReadError naming the file,
/// the byte offset and the record. Reads the record headers and the index, not the messages.
void CheckBagStructure(const std::filesystem::path& file);

}  // namespace lidarloop::io::detail

#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/point_map.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/posegraph/pose_graph_config.hpp"

namespace lidarloop::io {

/// What a run writes besides its results.
struct OutputConfig {
    /// detect keeps the full similarity matrix, and writes similarity.bin and the similarity
    /// images from it, when its n(n-1)/2 floats take at most this many MiB (1024: up to 23,170
    /// scans); a longer sequence is detected a query at a time, with the same results, in memory
    /// linear in the scans. 0: never keep it.
    std::size_t similarity_matrix_mib = 1024;

    /// True when the matrix of `scans` scans fits similarity_matrix_mib.
    bool KeepsSimilarityMatrix(std::size_t scans) const {
        const double bytes =
            0.5 * static_cast<double>(scans) * (static_cast<double>(scans) - 1) * sizeof(float);
        return bytes <= static_cast<double>(similarity_matrix_mib) * 1024.0 * 1024.0;
    }
    bool operator==(const OutputConfig&) const = default;
};

/// Every setting of a lidarloop run. The defaults live in the C++ config structs it holds; YAML
/// files and command-line flags override only the keys they name.
struct RunConfig {
    core::DescriptorConfig descriptor;   ///< keys `method`, `histogram.*`, `ndt.*`, `scancontext.*`
    pipeline::DetectorConfig detection;  ///< keys `detection.*`
    posegraph::PoseGraphConfig posegraph;  ///< keys `posegraph.*` (lidarloop optimise)
    core::MapConfig map;                   ///< keys `map.*` (optimise's maps, lidarloop map)
    OutputConfig output;                   ///< keys `output.*`

    void Validate() const {
        descriptor.Validate();
        detection.Validate();
        posegraph.Validate();
        map.Validate();
    }
};

/// The whole configuration as YAML, every key present, with a comment line per key.
std::string DumpConfigYaml(const RunConfig& config);

/// The declared parameters of the descriptor methods (histogram, ndt, scancontext, ...;
/// pipeline::ParameterSectionsOf) as a Markdown table, one row per parameter: `section.key`, its
/// value in `config` (as DumpConfigYaml writes it) and its help with unit and valid range, as
/// declared (docs/options.md). docs/cli.md holds its output.
std::string DumpParametersMarkdown(const RunConfig& config);

/// Keys of lidarloop 0.1 that moved: `histogram.threshold` and `ndt.threshold` are now
/// `detection.threshold`.
enum class LegacyKeys {
    /// A moved key with 0.1's default value (as every 0.1 config.yaml holds) is ignored; another
    /// value is a ReadError saying where it moved.
    kExplain,
    /// The value under the section of the file's method (histogram for height and range, ndt)
    /// becomes detection.threshold unless the file sets that; the other is ignored (a saved
    /// database: its threshold was the one its detection used).
    kMigrate,
};

/// Overrides the keys that `yaml_text` names in `config` and validates the result. `source`
/// (a file name) prefixes error messages. Throws ReadError for YAML syntax errors, unknown keys
/// (naming the key path and the valid keys), values of the wrong type, and invalid values.
void ApplyConfigYaml(const std::string& yaml_text, const std::string& source, RunConfig& config,
                     LegacyKeys legacy = LegacyKeys::kExplain);

/// Reads `file` and applies it on top of `base` (default: the built-in defaults).
RunConfig LoadConfigYaml(const std::filesystem::path& file, RunConfig base = {});

/// Writes DumpConfigYaml(config) to `file` (the effective config written beside results).
void WriteConfigYaml(const std::filesystem::path& file, const RunConfig& config);

}  // namespace lidarloop::io

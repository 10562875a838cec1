#include "lidarloop/io/config_yaml.hpp"

#include <algorithm>
#include <charconv>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/pipeline/scancontext_method.hpp"

namespace lidarloop::io {
namespace {

using detail::Quoted;

// lidarloop 0.1 kept the decision thresholds in the descriptor sections and wrote these defaults
// into every config.yaml and database; they are read only to say where the key moved.
constexpr double kLegacyHistogramThreshold = 0.005;
constexpr double kLegacyNdtThreshold = 0.0737;
// What an optional number that is not set reads and writes as.
constexpr char kUnsetValue[] = "default";

// An unknown key's message lists the section's keys up to this length; a longer section (the
// acceptance rule's) names the nearest key instead, so the message stays short.
constexpr std::size_t kMaxListedKeyChars = 300;
// Keys longer than this are no typo of a setting: no nearest key is looked for.
constexpr std::size_t kMaxTypoKeyChars = 80;

// Levenshtein distance: single-character insertions, deletions and substitutions.
std::size_t EditDistance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t above = row[j];
            row[j] = std::min({above + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
            diagonal = above;
        }
    }
    return row[b.size()];
}

// What an unknown key's message says of the keys valid in its section.
std::string ValidKeysHint(const std::string& unknown, const std::set<std::string>& known) {
    std::string listed;
    for (const auto& k : known) listed += (listed.empty() ? "" : ", ") + k;
    if (listed.size() <= kMaxListedKeyChars) return "valid here: " + listed;
    std::string hint;
    if (unknown.size() <= kMaxTypoKeyChars) {
        std::size_t nearest_distance = std::numeric_limits<std::size_t>::max();
        const std::string* nearest = nullptr;
        for (const auto& k : known) {
            const std::size_t distance = EditDistance(unknown, k);
            if (distance < nearest_distance) {
                nearest_distance = distance;
                nearest = &k;
            }
        }
        if (nearest && 2 * nearest_distance <= unknown.size())
            hint = "did you mean '" + *nearest + "'? ";
    }
    return hint + "`lidarloop dump-config` lists the " + std::to_string(known.size()) +
           " valid here";
}

std::string ThresholdHelp() {
    using detail::ShortNumber;
    return "tau (height, range: a loop when W <= tau), t_d (ndt: sigma' < t_d) or d "
           "(scancontext: d <= it); default: the method's (height " +
           ShortNumber(pipeline::DefaultThreshold(core::Method::kHeight)) + ", range " +
           ShortNumber(pipeline::DefaultThreshold(core::Method::kRange)) + ", ndt " +
           ShortNumber(pipeline::DefaultThreshold(core::Method::kNdt)) + ", scancontext " +
           ShortNumber(pipeline::DefaultThreshold(pipeline::ScanContextMethod::kMethod)) + ")";
}

std::string MethodHelp() { return "descriptor: " + pipeline::MethodNamesText(" | "); }

// The one list of keys. Both the writer and the reader walk it, so a key cannot exist in one and
// be missing in the other. `visitor.Field(key, value, help)`, `visitor.Section(key, struct)`,
// `visitor.Moved(key, new_key, legacy_default)` for a key that moved elsewhere.

// A struct that declares its parameters (core/parameters.hpp): each is a Field, its key and
// help as declared.
template <typename Config, typename Visitor>
void VisitDeclared(Config& c, Visitor& v) {
    Config::Declare(c, [&](auto& value, const core::ParameterInfo& info) {
        v.Field(std::string(info.key).c_str(), value, std::string(info.help));
    });
}

template <typename Visitor>
void VisitFields(core::HistogramConfig& c, Visitor& v) {
    VisitDeclared(c, v);
    v.Moved("threshold", "detection.threshold", kLegacyHistogramThreshold);
}

template <typename Visitor>
void VisitFields(core::NdtConfig& c, Visitor& v) {
    VisitDeclared(c, v);
    v.Moved("threshold", "detection.threshold", kLegacyNdtThreshold);
}

// A registered method's parameters (core::MethodParameters): each declared parameter becomes a
// Field of `visitor`, its key and help as declared.
template <typename Visitor>
class FieldAdapter final : public core::ParameterVisitor {
public:
    explicit FieldAdapter(Visitor& visitor) : visitor_(visitor) {}
    void Visit(const core::ParameterInfo& i, bool& value) override { Forward(i, value); }
    void Visit(const core::ParameterInfo& i, int& value) override { Forward(i, value); }
    void Visit(const core::ParameterInfo& i, std::size_t& value) override { Forward(i, value); }
    void Visit(const core::ParameterInfo& i, double& value) override { Forward(i, value); }
    void Visit(const core::ParameterInfo& i, std::optional<double>& value) override {
        Forward(i, value);
    }
    void Visit(const core::ParameterInfo& i, std::vector<double>& value) override {
        Forward(i, value);
    }
    void Visit(const core::ParameterInfo& i, std::string& value) override { Forward(i, value); }

private:
    template <typename T>
    void Forward(const core::ParameterInfo& info, T& value) {
        visitor_.Field(std::string(info.key).c_str(), value, std::string(info.help));
    }
    Visitor& visitor_;
};

template <typename Visitor>
void VisitFields(core::MethodParameters& c, Visitor& v) {
    FieldAdapter<Visitor> adapter(v);
    c.Visit(adapter);
}

template <typename Visitor>
void VisitFields(pipeline::DetectorConfig& c, Visitor& v) {
    v.Field("min_gap", c.min_gap.value, "S: candidates are at least this far back (Magnusson)");
    v.Field("min_gap_unit", c.min_gap.unit,
            "unit of min_gap: scans | seconds | metres (of path travelled)");
    v.Field("min_path_m", c.min_path_m,
            "and more than this much path back (metres), where the odometry or poses give it");
    v.Field("top_k", c.top_k, "candidates reported per query scan");
    v.Field("odometry_shortlist", c.odometry_shortlist,
            "with the odometry: top_k nearest view centres of this many best-ranked scans");
    v.Field("layout_shortlist", c.layout_shortlist,
            "verifying without odometry: top_k most alike layouts of this many best-ranked scans "
            "(0: rank order)");
    v.Field("threshold", c.threshold, ThresholdHelp());
    v.Field("verify", c.verify,
            "register candidates and accept only verified loops (section verification)");
    v.Field("stop_at_first_loop", c.stop_at_first_loop,
            "register candidates in rank order and stop at the first accepted one");
}

template <typename Visitor>
void VisitFields(registration::ScanReductionConfig& c, Visitor& v) {
    v.Field("min_range_m", c.min_range_m, "closer points are dropped (the vehicle)");
    v.Field("max_range_m", c.max_range_m, "farther points are dropped");
    v.Field("voxel_m", c.voxel_m, "edge of the voxels a scan is averaged into");
    v.Field("normal_neighbors", c.normal_neighbors, "voxel centroids in a normal's fit");
    v.Field("structure_min_tilt_deg", c.structure_min_tilt_deg,
            "structure points: normal at least this far from vertical");
    v.Field("distinctive_neighbors", c.distinctive_neighbors,
            "centroids that decide whether a structure point is on a large plane");
    v.Field("max_plane_variation", c.max_plane_variation, "largest surface variation of a plane");
    v.Field("max_structure_points", c.max_structure_points, "structure points kept per scan");
    v.Field("max_ground_points", c.max_ground_points, "other (ground) points kept per scan");
    v.Field("submap_path_m", c.submap_path_m,
            "a scan merged with its neighbours this much path either side (0: off; dense "
            "scans stay alone)");
    v.Field("submap_max_scans", c.submap_max_scans, "neighbours merged per side, at most");
    v.Field("submap_max_points", c.submap_max_points,
            "points merged at most, nearest neighbours in path first");
}

template <typename Visitor>
void VisitFields(registration::CoarseConfig& c, Visitor& v) {
    v.Field("cell_m", c.cell_m, "cell of the top-down structure images");
    v.Field("grid_cells", c.grid_cells, "image edge in cells (power of two)");
    v.Field("yaw_step_deg", c.yaw_step_deg, "yaw search step over the full circle");
    v.Field("max_translation_m", c.max_translation_m, "largest planar offset searched");
    v.Field("hypotheses", c.hypotheses, "best coarse poses refined by ICP");
    v.Field("min_hypothesis_score_ratio", c.min_hypothesis_score_ratio,
            "a coarse pose after the best is refined only with this share of its score");
    v.Field("max_peak_beyond_loop_m", c.max_peak_beyond_loop_m,
            "a coarse pose is refined only within max_loop_distance_m plus this (m)");
    v.Field("rival_hypotheses", c.rival_hypotheses,
            "further coarse poses the ambiguity test registers after an acceptance");
    v.Field("peaks_per_yaw", c.peaks_per_yaw, "translation peaks kept per yaw");
    v.Field("layout_yaw_window_deg", c.layout_yaw_window_deg,
            "without odometry, yaws searched around the layouts' and half a turn from it");
    v.Field("better_half_turn_only", c.better_half_turn_only,
            "without odometry, search only the layouts' half turn whose centre correlates better");
}

template <typename Visitor>
void VisitFields(registration::IcpConfig& c, Visitor& v) {
    v.Field("initial_correspondence_m", c.initial_correspondence_m,
            "pairing distance of the first stage; halved per stage");
    v.Field("final_correspondence_m", c.final_correspondence_m, "of the last stage");
    v.Field("max_iterations_per_stage", c.max_iterations_per_stage, "Gauss-Newton steps");
    v.Field("convergence_step", c.convergence_step, "a stage ends below this step (m + rad)");
    v.Field("max_structure_points", c.max_structure_points, "query structure points paired");
    v.Field("max_ground_points", c.max_ground_points, "query ground points paired");
    v.Field("first_stage_structure_points", c.first_stage_structure_points,
            "query structure points the first stage pairs");
    v.Field("first_stage_ground_points", c.first_stage_ground_points,
            "query ground points the first stage pairs");
    v.Field("abandon_below_overlap", c.abandon_below_overlap,
            "a pose overlapping less after the first stage is abandoned");
    v.Field("abandon_above_shifted_overlap", c.abandon_above_shifted_overlap,
            "without odometry, a pose sliding more freely after the first stage is abandoned");
    v.Field("aligned_step_factor", c.aligned_step_factor,
            "a step along the previous one moves up to this many times as far (1: plain)");
    v.Field("rival_step_factor", c.rival_step_factor,
            "aligned_step_factor of the ambiguity test's ICP toward a rival pose");
}

template <typename Visitor>
void VisitFields(registration::AcceptanceConfig& c, Visitor& v) {
    v.Field("overlap_radius_m", c.overlap_radius_m, "a structure point's partner is this close");
    v.Field("overlap_plane_m", c.overlap_plane_m, "and its plane passes this close");
    v.Field("overlap_range_m", c.overlap_range_m, "only points this close to both sensors count");
    v.Field("min_overlap", c.min_overlap, "share of structure points overlapping, each way");
    v.Field("min_distinctive_overlap", c.min_distinctive_overlap,
            "the same for the structure points off large planes");
    v.Field("min_overlapping_points", c.min_overlapping_points, "overlapping points, each way");
    v.Field("overlap_confidence_z", c.overlap_confidence_z,
            "fewer suffice where the share's lower bound (this many standard errors) passes");
    v.Field("max_rmse_ratio", c.max_rmse_ratio,
            "RMS plane distance of the overlap over the scans' own roughness, at most");
    v.Field("max_rmse_ratio_with_odometry", c.max_rmse_ratio_with_odometry,
            "the same where the odometry judges the loop (--odometry)");
    v.Field("min_allowed_rmse_m", c.min_allowed_rmse_m, "the allowed RMS is at least this");
    v.Field("max_rmse_m", c.max_rmse_m, "and at most this");
    v.Field("min_constraining_points", c.min_constraining_points,
            "overlapping points facing the weakest direction, at least");
    v.Field("min_constraining_points_with_odometry", c.min_constraining_points_with_odometry,
            "the same where the odometry judges the loop (--odometry)");
    v.Field("min_constraining_points_with_motion", c.min_constraining_points_with_motion,
            "the same where the scans' own registered motion judges the loop (offline)");
    v.Field("degeneracy_shift_m", c.degeneracy_shift_m, "shift along the weakest direction");
    v.Field("max_shifted_overlap_ratio", c.max_shifted_overlap_ratio,
            "share of the points pinning that direction still overlapping there, at most");
    v.Field("max_rival_overlap_ratio", c.max_rival_overlap_ratio,
            "another pose may reach at most this share of the accepted overlap");
    v.Field("max_loop_distance_m", c.max_loop_distance_m,
            "the registered sensors of a loop are at most this far apart");
    v.Field("min_neighbour_overlap_ratio", c.min_neighbour_overlap_ratio,
            "without odometry, a loop's distinctive overlap over its scans' with their neighbours, "
            "at least (0: off)");
    v.Field("revisit_path_m", c.revisit_path_m,
            "with odometry, loops whose queries and matches lie this close in path must agree; "
            "of two chains that do not, the shorter is rejected (0: off)");
    v.Field("motion_max_turn_deg", c.motion_max_turn_deg,
            "without odometry, where the scans from match to query never turn more than this, "
            "their chained motion must allow the loop (0: off)");
    v.Field("motion_drift_m", c.motion_drift_m, "the chain may be off by this, metres,");
    v.Field("motion_drift_ratio", c.motion_drift_ratio, "plus this share of its path");
}

template <typename Visitor>
void VisitFields(registration::VerificationConfig& c, Visitor& v) {
    v.Section("reduction", c.reduction);
    v.Section("coarse", c.coarse);
    v.Section("icp", c.icp);
    v.Section("acceptance", c.acceptance);
}

template <typename Visitor>
void VisitFields(posegraph::InformationConfig& c, Visitor& v) {
    v.Field("odometry_translation_sigma_m_per_sqrt_m", c.odometry_translation_sigma_m_per_sqrt_m,
            "odometry position drift: sigma^2 grows by this^2 per metre travelled");
    v.Field("odometry_rotation_sigma_deg_per_sqrt_m", c.odometry_rotation_sigma_deg_per_sqrt_m,
            "odometry rotation drift: sigma^2 grows by this^2 per metre travelled");
    v.Field("odometry_min_translation_sigma_m", c.odometry_min_translation_sigma_m,
            "odometry step sigma at standstill, metres");
    v.Field("odometry_min_rotation_sigma_deg", c.odometry_min_rotation_sigma_deg,
            "odometry step sigma at standstill, degrees");
    v.Field("loop_translation_sigma_m", c.loop_translation_sigma_m,
            "loop sigma, combined with the verification RMSE");
    v.Field("loop_rotation_sigma_deg", c.loop_rotation_sigma_deg, "loop rotation sigma");
    v.Field("loop_reference_overlap", c.loop_reference_overlap,
            "loop information scales with overlap / this, within [0.2, 2]");
}

template <typename Visitor>
void VisitFields(posegraph::RobustConfig& c, Visitor& v) {
    v.Field("gate_sigmas", c.gate_sigmas,
            "loops further from the odometry than this many sigmas of its drift are rejected");
    v.Field("gate_min_translation_m", c.gate_min_translation_m, "added to the gate, metres");
    v.Field("gate_min_rotation_deg", c.gate_min_rotation_deg, "added to the gate, degrees");
    v.Field("gate_translation_percent", c.gate_translation_percent,
            "systematic drift allowed, per cent of the path");
    v.Field("gate_rotation_deg_per_100m", c.gate_rotation_deg_per_100m,
            "systematic drift allowed, degrees per 100 m of path");
    v.Field("support_window_m", c.support_window_m,
            "loops whose ends lie this close along the path check each other");
    v.Field("min_support", c.min_support,
            "consistent neighbouring loops a loop needs to enter the first optimisation");
    v.Field("cauchy_scale", c.cauchy_scale, "Cauchy loss scale on loops, whitened units");
    v.Field("reject_sigmas", c.reject_sigmas,
            "loops with a larger whitened residual after optimising are dropped");
    v.Field("scale_step", c.scale_step, "the Cauchy scale shrinks by this factor per round");
    v.Field("max_reject_rounds", c.max_reject_rounds, "rounds of dropping loops and re-solving");
}

template <typename Visitor>
void VisitFields(posegraph::PoseGraphConfig& c, Visitor& v) {
    v.Section("information", c.information);
    v.Section("robust", c.robust);
    v.Field("max_odometry_step_m", c.max_odometry_step_m,
            "optimise: odometry moving farther between two scans is an error (a jump or reset), m");
    v.Field("max_loops_per_scan", c.max_loops_per_scan,
            "optimise: verified loops taken per scan, the best and then earlier passes");
    v.Field("min_loop_separation_m", c.min_loop_separation_m,
            "optimise: a scan's further loops lie this much path from the matches taken, m");
    v.Field("max_iterations", c.max_iterations, "Ceres trust-region iterations per solve");
    v.Field("threads", c.threads, "Ceres threads");
}

template <typename Visitor>
void VisitFields(core::MapConfig& c, Visitor& v) {
    v.Field("voxel_m", c.voxel_m,
            "optimise, map: edge of the voxels a map's placed points are averaged into, m");
    v.Field("max_points", c.max_points,
            "most points of a map; a larger map gets a coarser voxel (doubled until it fits)");
}

template <typename Visitor>
void VisitFields(OutputConfig& c, Visitor& v) {
    v.Field("similarity_matrix_mib", c.similarity_matrix_mib,
            "detect keeps the similarity matrix (similarity.bin, images) up to this size; 0 never");
}

template <typename Visitor>
void VisitFields(RunConfig& c, Visitor& v) {
    v.Field("method", c.descriptor.method, MethodHelp());
    v.Section(core::HistogramConfig::kSection, c.descriptor.histogram);
    v.Section(core::NdtConfig::kSection, c.descriptor.ndt);
    v.MethodSections(c.descriptor);  // scancontext and any other registered method's
    v.Section("detection", c.detection);
    v.Section("verification", c.detection.verification);
    v.Section("posegraph", c.posegraph);
    v.Section("map", c.map);
    v.Section("output", c.output);
}

std::string EnumName(const core::Method& m) { return core::ToString(m); }
std::string EnumName(core::UpVectorMode m) { return core::ToString(m); }
std::string EnumName(core::OutOfRangePolicy m) { return core::ToString(m); }
std::string EnumName(core::MinGap::Unit u) { return core::ToString(u); }
void ParseEnum(const std::string& s, core::Method& m) { m = pipeline::ParseMethod(s); }
void ParseEnum(const std::string& s, core::UpVectorMode& m) { m = core::ParseUpVectorMode(s); }
void ParseEnum(const std::string& s, core::MinGap::Unit& u) { u = core::ParseMinGapUnit(s); }
void ParseEnum(const std::string& s, core::OutOfRangePolicy& m) {
    m = core::ParseOutOfRangePolicy(s);
}

// Values written and read by their names: enums and the method.
template <typename T>
constexpr bool kIsNamed = std::is_enum_v<T> || std::is_same_v<T, core::Method>;

class YamlWriter {
public:
    template <typename T>
    void Field(const char* key, const T& value, const std::string& help) {
        out_ << indent_ << key << ": ";
        if constexpr (std::is_same_v<T, std::optional<double>>) {
            if (value) {
                WriteNumber(*value);
            } else {
                out_ << kUnsetValue;
            }
        } else if constexpr (kIsNamed<T>) {
            out_ << EnumName(value);
        } else if constexpr (std::is_same_v<T, bool>) {
            out_ << (value ? "true" : "false");
        } else if constexpr (std::is_same_v<T, std::string>) {
            out_ << value;
        } else if constexpr (std::is_same_v<T, std::vector<double>>) {
            out_ << "[";
            for (std::size_t i = 0; i < value.size(); ++i) {
                out_ << (i > 0 ? ", " : "");
                WriteNumber(value[i]);
            }
            out_ << "]";
        } else {
            WriteNumber(value);
        }
        out_ << "  # " << help << "\n";
    }
    template <typename Number>
    void WriteNumber(Number value) {
        // Shortest text that reads back to the same value (0.005, not 0.005000000000000001).
        char buffer[64];
        const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
        out_.write(buffer, result.ptr - buffer);
    }
    void Moved(const char*, const char*, double) {}  // written under its new key only
    // Every registered method's section, as held or with its defaults.
    void MethodSections(const core::DescriptorConfig& descriptor) {
        for (core::MethodParameters& p : pipeline::MethodParametersOf(descriptor))
            Section(p.section().c_str(), p);
    }
    template <typename Struct>
    void Section(const char* key, Struct& section) {
        out_ << indent_ << key << ":\n";
        const std::string outer = indent_;
        indent_ += "  ";
        VisitFields(section, *this);
        indent_ = outer;
    }
    std::string str() const { return out_.str(); }

private:
    std::ostringstream out_;
    std::string indent_;
};

// What a key of type T takes, for the message of a value it cannot: an integer type says its
// range, since yaml-cpp refuses a number beyond it (-1 for a count) as "not an integer".
template <typename T>
std::string ExpectedKind() {
    if constexpr (std::is_same_v<T, std::optional<double>>) return "a number or 'default'";
    if constexpr (std::is_same_v<T, bool>) return "true or false";
    if constexpr (std::is_same_v<T, std::vector<double>>) return "a list of numbers";
    if constexpr (std::is_same_v<T, std::string>) return "a name";
    if constexpr (std::is_integral_v<T>) {
        return "an integer in [" + std::to_string(std::numeric_limits<T>::min()) + ", " +
               std::to_string(std::numeric_limits<T>::max()) + "]";
    }
    return "a number";
}

class YamlReader {
public:
    /// `moved` collects the values of moved keys by their old path (LegacyKeys::kMigrate).
    YamlReader(const YAML::Node& node, std::string source, std::string prefix, LegacyKeys legacy,
               std::map<std::string, double>* moved)
        : node_(node),
          source_(std::move(source)),
          prefix_(std::move(prefix)),
          legacy_(legacy),
          moved_(moved) {}

    template <typename T>
    void Field(const char* key, T& value, const std::string&) {
        known_.insert(key);
        const YAML::Node child = node_[key];
        if (!child) return;
        if constexpr (std::is_same_v<T, std::optional<double>>) {
            if (child.IsNull() || (child.IsScalar() && child.Scalar() == kUnsetValue)) {
                value.reset();
                return;
            }
        }
        constexpr bool kIsList = std::is_same_v<T, std::vector<double>>;
        if (kIsList && !child.IsSequence()) Fail(key, "expected a list of numbers like [3, 6]");
        if (!kIsList && !child.IsScalar()) Fail(key, "expected a single value");
        try {
            if constexpr (kIsList) {
                value = child.as<std::vector<double>>();
            } else if constexpr (std::is_same_v<T, std::optional<double>>) {
                value = child.as<double>();
            } else if constexpr (kIsNamed<T>) {
                ParseEnum(child.as<std::string>(), value);
            } else {
                value = child.as<T>();
            }
        } catch (const YAML::BadConversion&) {
            Fail(key, std::string("expected ") + ExpectedKind<T>() + ", got " +
                          Quoted(YAML::Dump(child)));
        } catch (const core::ConfigError& e) {
            Fail(key, e.what());
        }
    }
    // lidarloop 0.1's key: its default (which every 0.1 config.yaml and database holds) is
    // ignored, as it is the method's default now; another value says where it moved.
    void Moved(const char* key, const char* new_key, double legacy_default) {
        known_.insert(key);
        const YAML::Node child = node_[key];
        if (!child) return;
        const std::optional<double> value =
            child.IsScalar() ? detail::ParseDouble(child.Scalar()) : std::nullopt;
        if (legacy_ == LegacyKeys::kMigrate && value) {
            (*moved_)[prefix_ + key] = *value;
            return;
        }
        if (value == legacy_default) return;
        std::string written;  // the value as the new key takes it; a non-number quoted and cut
        if (value) {
            detail::AppendNumber(written, *value, ' ');
            written.pop_back();
        } else {
            written = Quoted(YAML::Dump(child));
        }
        Fail(key, std::string("moved to '") + new_key +
                      "' (the decision threshold is no longer a descriptor parameter and applies "
                      "to the run's method; this one was for " +
                      (prefix_ == "ndt." ? "ndt" : "height and range") + "): write " + new_key +
                      ": " + written + " instead");
    }
    template <typename Struct>
    void Section(const char* key, Struct& section) {
        known_.insert(key);
        const YAML::Node child = node_[key];
        if (!child || child.IsNull()) return;
        if (!child.IsMap()) Fail(key, "expected a section of keys");
        YamlReader reader(child, source_, prefix_ + key + ".", legacy_, moved_);
        reader.RejectBadKeys();
        VisitFields(section, reader);
        reader.RejectUnknownKeys();
    }
    // The section of every registered method with parameters: read into what `descriptor`
    // holds (or the defaults) and held from then on.
    void MethodSections(core::DescriptorConfig& descriptor) {
        for (core::MethodParameters& p : pipeline::MethodParametersOf(descriptor)) {
            const std::string key = p.section();
            Section(key.c_str(), p);
            if (node_[key]) descriptor.methods.Set(std::move(p));
        }
    }
    // yaml-cpp 0.7 keeps both entries of a repeated key and node[key] finds the first, so the
    // second would be ignored silently. Checked before any value is read, so that the repeat is
    // what the message names.
    void RejectBadKeys() const {
        std::map<std::string, int> first_line;
        for (const auto& entry : node_) {
            if (!entry.first.IsScalar()) FailKeyNotAName(entry.first);
            const int line = entry.first.Mark().line + 1;
            const auto [it, inserted] = first_line.emplace(entry.first.Scalar(), line);
            if (inserted) continue;
            throw ReadError(
                source_, "line " + std::to_string(line) + ": key " + Quoted(prefix_ + it->first) +
                             " appears twice (first on line " + std::to_string(it->second) + ")");
        }
    }
    void RejectUnknownKeys() const {
        for (const auto& entry : node_) {
            const std::string& key = entry.first.Scalar();
            if (known_.count(key) != 0) continue;
            Fail(key, "unknown key (" + ValidKeysHint(key, known_) + ")");
        }
    }

private:
    // A known key is named whole (the longest are over Quoted's 40 characters); a user's
    // unknown one is quoted safely.
    [[noreturn]] void Fail(const std::string& key, const std::string& problem) const {
        const std::string named =
            known_.count(key) != 0 ? "'" + prefix_ + key + "'" : Quoted(prefix_ + key);
        throw ReadError(source_, "key " + named + ": " + problem);
    }
    // A key that is a list, a map or empty (`[a]: 1`, `{x: 1}: 2`, `? :`) names no setting.
    [[noreturn]] void FailKeyNotAName(const YAML::Node& key) const {
        const char* kind = key.IsSequence() ? "a list" : key.IsMap() ? "a map" : "empty";
        const std::string where =
            prefix_.empty() ? "at the top level"
                            : "in section '" + prefix_.substr(0, prefix_.size() - 1) + "'";
        throw ReadError(source_, "line " + std::to_string(key.Mark().line + 1) + ": a key " +
                                     where + " is " + kind + ", not a name");
    }

    YAML::Node node_;
    std::string source_;
    std::string prefix_;
    LegacyKeys legacy_;
    std::map<std::string, double>* moved_;
    std::set<std::string> known_;
};

// lidarloop 0.1 kept tau under histogram (height, range) and t_d under ndt.
void MigrateThreshold(const std::map<std::string, double>& moved, RunConfig& config) {
    if (config.detection.threshold) return;
    const char* key =
        core::IsHistogramMethod(config.descriptor.method) ? "histogram.threshold" : "ndt.threshold";
    if (const auto it = moved.find(key); it != moved.end()) config.detection.threshold = it->second;
}

}  // namespace

std::string DumpConfigYaml(const RunConfig& config) {
    YamlWriter writer;
    RunConfig copy = config;  // the visitor is shared with the reader, which needs mutable access
    VisitFields(copy, writer);
    return "# lidarloop configuration; every key is optional and overrides the default.\n" +
           writer.str();
}

namespace {

// One table row per declared parameter: key, default (as dump-config writes it), and the help
// with the unit and the valid range.
class MarkdownRows final : public core::ParameterVisitor {
public:
    explicit MarkdownRows(std::string section) : section_(std::move(section)) {}
    void Visit(const core::ParameterInfo& i, bool& value) override { Row(i, value); }
    void Visit(const core::ParameterInfo& i, int& value) override { Row(i, value); }
    void Visit(const core::ParameterInfo& i, std::size_t& value) override { Row(i, value); }
    void Visit(const core::ParameterInfo& i, double& value) override { Row(i, value); }
    void Visit(const core::ParameterInfo& i, std::optional<double>& value) override {
        Row(i, value);
    }
    void Visit(const core::ParameterInfo& i, std::vector<double>& value) override { Row(i, value); }
    void Visit(const core::ParameterInfo& i, std::string& value) override { Row(i, value); }
    std::string str() const { return out_; }

private:
    template <typename T>
    void Row(const core::ParameterInfo& info, T& value) {
        YamlWriter writer;  // the default exactly as dump-config writes it
        writer.Field("k", value, "");
        std::string text = writer.str();
        text = text.substr(3, text.find("  #") - 3);
        bool code = std::is_same_v<T, std::string>;  // names in code, as in the docs
        if constexpr (std::is_same_v<T, std::optional<double>>) code = !value.has_value();
        out_ += "| `" + section_ + "." + std::string(info.key) + "` | " +
                (code ? "`" + text + "`" : text) + " | ";
        for (const char c : info.help) out_ += c == '|' ? std::string("\\|") : std::string(1, c);
        std::string limits;
        if (!info.unit.empty()) limits += std::string(info.unit);
        if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
            if (info.HasRange())
                limits += (limits.empty() ? "" : ", ") + core::RangeText<T>(info, " to ");
        }
        if (!limits.empty()) out_ += " (" + limits + ")";
        out_ += " |\n";
    }
    std::string section_;
    std::string out_;
};

}  // namespace

std::string DumpParametersMarkdown(const RunConfig& config) {
    std::string text = "| key | default | meaning |\n|---|---|---|\n";
    for (const pipeline::ParameterSection& section :
         pipeline::ParameterSectionsOf(config.descriptor)) {
        MarkdownRows rows(section.name);
        section.visit(rows);
        text += rows.str();
    }
    return text;
}

void ApplyConfigYaml(const std::string& yaml_text, const std::string& source, RunConfig& config,
                     LegacyKeys legacy) {
    YAML::Node root;
    RunConfig updated = config;
    try {
        root = YAML::Load(yaml_text);
        if (!root || root.IsNull()) return;  // an empty file overrides nothing
        if (!root.IsMap()) throw ReadError(source, "expected a map of keys at the top level");
        std::map<std::string, double> moved;
        YamlReader reader(root, source, "", legacy, &moved);
        reader.RejectBadKeys();
        VisitFields(updated, reader);
        reader.RejectUnknownKeys();
        MigrateThreshold(moved, updated);
    } catch (const YAML::ParserException& e) {
        throw ReadError(source, "line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
    } catch (const YAML::Exception& e) {
        // The reader checks every node it converts; this is the net for what it does not foresee.
        throw ReadError(source, std::string("unreadable YAML: ") + e.what());
    }
    try {
        updated.Validate();
    } catch (const core::ConfigError& e) {
        throw ReadError(source, e.what());
    }
    config = updated;
}

RunConfig LoadConfigYaml(const std::filesystem::path& file, RunConfig base) {
    auto in = detail::OpenForReading(file, /*binary=*/false);
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    ApplyConfigYaml(text, file.string(), base);
    return base;
}

void WriteConfigYaml(const std::filesystem::path& file, const RunConfig& config) {
    auto out = detail::OpenForWriting(file, /*binary=*/false);
    out << DumpConfigYaml(config);
    out.close();  // flushes: a full disk fails here, not silently in the destructor
    if (!out) throw WriteError(file, "write failed");
}

}  // namespace lidarloop::io

#include "lidarloop/io/config_yaml.hpp"

#include <charconv>
#include <iterator>
#include <set>
#include <sstream>
#include <type_traits>

#include <yaml-cpp/yaml.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/text_parsing.hpp"

namespace lidarloop::io {
namespace {

// The one list of keys. Both the writer and the reader walk it, so a key cannot exist in one and
// be missing in the other. `visitor.Field(key, value, help)`, `visitor.Section(key, struct)`.
template <typename Visitor>
void VisitFields(core::HistogramConfig& c, Visitor& v) {
    v.Field("bins", c.bins, "b, number of buckets");
    v.Field("up_vector", c.up_vector, "height projection up vector: fixed (0,0,1) | pca");
    v.Field("sensor_height_m", c.sensor_height_m, "added to heights so that 0 is the ground");
    v.Field("height_min_m", c.height_min_m, "v_min of the height histogram");
    v.Field("height_max_m", c.height_max_m, "v_max of the height histogram");
    v.Field("range_min_m", c.range_min_m, "v_min of the range histogram");
    v.Field("range_max_m", c.range_max_m, "v_max of the range histogram");
    v.Field("out_of_range", c.out_of_range, "values outside [v_min, v_max]: clamp | drop");
    v.Field("threshold", c.threshold, "tau: a pair is a loop when W <= tau (Roehling eq. 7)");
}

template <typename Visitor>
void VisitFields(RunConfig& c, Visitor& v) {
    v.Field("method", c.descriptor.method, "descriptor: height | range");
    v.Section("histogram", c.descriptor.histogram);
}

std::string EnumName(core::Method m) { return core::ToString(m); }
std::string EnumName(core::UpVectorMode m) { return core::ToString(m); }
std::string EnumName(core::OutOfRangePolicy m) { return core::ToString(m); }
void ParseEnum(const std::string& s, core::Method& m) { m = core::ParseMethod(s); }
void ParseEnum(const std::string& s, core::UpVectorMode& m) { m = core::ParseUpVectorMode(s); }
void ParseEnum(const std::string& s, core::OutOfRangePolicy& m) {
    m = core::ParseOutOfRangePolicy(s);
}

class YamlWriter {
public:
    template <typename T>
    void Field(const char* key, const T& value, const char* help) {
        out_ << indent_ << key << ": ";
        if constexpr (std::is_enum_v<T>) {
            out_ << EnumName(value);
        } else {
            // Shortest text that reads back to the same value (0.005, not 0.005000000000000001).
            char buffer[64];
            const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
            out_.write(buffer, result.ptr - buffer);
        }
        out_ << "  # " << help << "\n";
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

class YamlReader {
public:
    YamlReader(const YAML::Node& node, std::string source, std::string prefix)
        : node_(node), source_(std::move(source)), prefix_(std::move(prefix)) {}

    template <typename T>
    void Field(const char* key, T& value, const char*) {
        known_.insert(key);
        const YAML::Node child = node_[key];
        if (!child) return;
        if (!child.IsScalar()) Fail(key, "expected a single value");
        try {
            if constexpr (std::is_enum_v<T>) {
                ParseEnum(child.as<std::string>(), value);
            } else {
                value = child.as<T>();
            }
        } catch (const YAML::BadConversion&) {
            Fail(key, std::string("expected ") + (std::is_integral_v<T> ? "an integer" : "a number") +
                          ", got '" + child.as<std::string>() + "'");
        } catch (const core::ConfigError& e) {
            Fail(key, e.what());
        }
    }
    template <typename Struct>
    void Section(const char* key, Struct& section) {
        known_.insert(key);
        const YAML::Node child = node_[key];
        if (!child || child.IsNull()) return;
        if (!child.IsMap()) Fail(key, "expected a section of keys");
        YamlReader reader(child, source_, prefix_ + key + ".");
        VisitFields(section, reader);
        reader.RejectUnknownKeys();
    }
    void RejectUnknownKeys() const {
        for (const auto& entry : node_) {
            const auto key = entry.first.as<std::string>();
            if (known_.count(key) != 0) continue;
            std::string valid;
            for (const auto& k : known_) valid += (valid.empty() ? "" : ", ") + k;
            Fail(key, "unknown key (valid here: " + valid + ")");
        }
    }

private:
    [[noreturn]] void Fail(const std::string& key, const std::string& problem) const {
        throw ReadError(source_, "key '" + prefix_ + key + "': " + problem);
    }

    YAML::Node node_;
    std::string source_;
    std::string prefix_;
    std::set<std::string> known_;
};

}  // namespace

std::string DumpConfigYaml(const RunConfig& config) {
    YamlWriter writer;
    RunConfig copy = config;  // the visitor is shared with the reader, which needs mutable access
    VisitFields(copy, writer);
    return "# lidarloop configuration; every key is optional and overrides the default.\n" +
           writer.str();
}

void ApplyConfigYaml(const std::string& yaml_text, const std::string& source, RunConfig& config) {
    YAML::Node root;
    try {
        root = YAML::Load(yaml_text);
    } catch (const YAML::ParserException& e) {
        throw ReadError(source, "line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
    }
    if (!root || root.IsNull()) return;  // an empty file overrides nothing
    if (!root.IsMap()) throw ReadError(source, "expected a map of keys at the top level");
    RunConfig updated = config;
    YamlReader reader(root, source, "");
    VisitFields(updated, reader);
    reader.RejectUnknownKeys();
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
    if (!out) throw WriteError(file, "write failed");
}

}  // namespace lidarloop::io

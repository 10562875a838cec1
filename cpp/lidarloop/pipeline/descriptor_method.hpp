#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "lidarloop/core/byte_codec.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/point_cloud.hpp"

namespace lidarloop::pipeline {

/// A stored scan and its distance to a query.
struct Neighbor {
    std::size_t index = 0;
    double distance = 0.0;  ///< the method's distance: W (histograms), sigma' (NDT), ...
};

/// A descriptor made ready for many comparisons by the store that made it (e.g. a cumulative
/// histogram row). Only that store, and stores of the same method and config, compare with it.
class PreparedQuery {
public:
    virtual ~PreparedQuery() = default;
};

/// A number per valid scan that says how much work its descriptor was (e.g. NDT rotation
/// candidates), for timings.json.
struct WorkFigure {
    std::string name;            ///< e.g. "rotation_candidates_per_scan"
    std::vector<double> values;  ///< one per valid scan
};

class NeighborIndex;

/// The descriptors of a sequence of scans under one method and config, in scan order, kept in
/// the form that compares fastest. Entry i of a scan that could not be described is a
/// placeholder (AddMissing) that the database never compares. Not thread-safe for writing;
/// concurrent reads are safe.
class DescriptorStore {
public:
    virtual ~DescriptorStore() = default;
    /// A deep copy (DescriptorDatabase copies with it).
    virtual std::unique_ptr<DescriptorStore> Clone() const = 0;

    /// Appends the descriptor of the next scan (of this store's method and config).
    virtual void Add(const core::Descriptor& descriptor) = 0;
    /// Appends a placeholder for a scan that could not be described (never compared).
    virtual void AddMissing() = 0;
    /// The method's distance between stored scans i and j (both valid).
    virtual double Distance(std::size_t i, std::size_t j) const = 0;
    /// A descriptor (not stored) made ready for comparisons with the stored scans.
    virtual std::unique_ptr<PreparedQuery> Prepare(const core::Descriptor& descriptor) const = 0;
    /// Stored scan i (valid) made ready for comparisons, e.g. with another database's scans.
    virtual std::unique_ptr<PreparedQuery> PrepareStored(std::size_t i) const = 0;
    /// The distance between a query prepared by a store like this one and stored scan j (valid).
    virtual double Distance(const PreparedQuery& query, std::size_t j) const = 0;

    /// A k-nearest-neighbour index over this store, which must outlive it; nullptr when the
    /// method has none (the detector then compares every eligible scan). Exact unless its
    /// IsExact() says otherwise (scancontext's ring-key search).
    virtual std::unique_ptr<NeighborIndex> MakeIndex() const { return nullptr; }
    /// Per-scan work figures of the valid scans (`valid[i]` says which); none by default.
    virtual std::vector<WorkFigure> Work(const std::vector<std::uint8_t>& /*valid*/) const {
        return {};
    }

    /// Appends stored scan i (valid or a placeholder) to a saved database.
    virtual void Encode(std::size_t i, core::ByteWriter& out) const = 0;
    /// Reads one scan written by Encode and appends it (`valid` as saved); calls in.Fail for
    /// damaged data.
    virtual void Decode(core::ByteReader& in, bool valid) = 0;
};

/// Nearest-neighbour search over a store's valid scans, faster than comparing each.
class NeighborIndex {
public:
    virtual ~NeighborIndex() = default;
    /// Indexes scan `id` of the store (each once, in any order).
    virtual void Insert(std::size_t id) = 0;
    /// Indexes every scan of the store not yet indexed for which `include(id)` holds.
    virtual void InsertAll(const std::function<bool(std::size_t)>& include) = 0;
    /// The k indexed scans nearest to `query` for which `eligible(id)` holds (all when empty),
    /// sorted by (distance, index): exactly what comparing every such scan would give when
    /// IsExact(), else a subset ranked the same way.
    virtual std::vector<Neighbor> Search(
        const PreparedQuery& query, std::size_t k,
        const std::function<bool(std::size_t)>& eligible) const = 0;
    /// Whether Search always finds the true k nearest (true for the histogram index).
    virtual bool IsExact() const { return true; }
};

/// One place descriptor method: how a scan is described, how two descriptions compare, how
/// many are stored (and saved), and what decides a loop. Register a new one with RegisterMethod;
/// the database, the detector, the file formats and every run reach methods only through this.
/// Implementations must be thread-safe (Describe and Distance run from many threads).
class DescriptorMethod {
public:
    explicit DescriptorMethod(core::Method method) : method_(method) {}
    virtual ~DescriptorMethod() = default;

    /// The method's identity; name() is what configs and --method call it.
    const core::Method& method() const { return method_; }
    std::string name() const { return core::ToString(method_); }

    /// The descriptor of `cloud`; core::EmptyInputError when nothing in it is usable.
    virtual core::Descriptor Describe(const core::PointCloud& cloud,
                                      const core::DescriptorConfig& config) const = 0;
    /// Describe for points owned elsewhere (e.g. a NumPy array). By default they are copied
    /// into a PointCloud for Describe; a method that reads a view directly overrides this.
    virtual core::Descriptor DescribeView(core::PointsView points,
                                          const core::DescriptorConfig& config) const;
    /// The distance between two descriptors of this method: smaller is more similar, 0 for
    /// equal descriptors, symmetric.
    virtual double Distance(const core::Descriptor& a, const core::Descriptor& b) const = 0;
    /// An empty store for descriptors made under `config` (validated).
    virtual std::unique_ptr<DescriptorStore> MakeStore(
        const core::DescriptorConfig& config) const = 0;

    /// The method's own parameters with their defaults, under its name as their section: YAML
    /// `<name>:` and dump-config, flags --<name>-<key>, Python keywords of describe
    /// (docs/options.md). Describe and MakeStore read them with
    /// config.methods.Get<Config>(name()). nullopt (the default): no parameters of its own.
    virtual std::optional<core::MethodParameters> DefaultParameters() const { return std::nullopt; }

    /// The default decision threshold (detection.threshold when it is not set).
    virtual double DefaultThreshold() const = 0;
    /// Whether `distance` says "same place" under `threshold` (default: distance <= threshold).
    virtual bool IsMatch(double distance, double threshold) const { return distance <= threshold; }
    /// ConfigError naming detection.threshold unless `threshold` can decide this method's
    /// distances (default: finite and >= 0).
    virtual void ValidateThreshold(double threshold) const;

private:
    core::Method method_;
};

/// Adds `method` to the methods every part of lidarloop knows, under its name (from then on
/// ParseMethod finds it, `method: <name>` in a config and `--method <name>` select it).
/// ConfigError when the name is taken. Thread-safe.
void RegisterMethod(std::shared_ptr<const DescriptorMethod> method);

/// The registered method `method` names; ConfigError listing the registered names otherwise.
/// Thread-safe.
const DescriptorMethod& MethodOf(const core::Method& method);

/// The method called `name`; ConfigError listing the registered names otherwise.
core::Method ParseMethod(std::string_view name);

/// The names of every registered method: height, range, ndt first, then in registration order.
std::vector<std::string> MethodNames();
/// MethodNames() joined by `separator` ("height | range | ndt"), for help texts and messages.
std::string MethodNamesText(std::string_view separator);

/// The parameters of every registered method that has any (DefaultParameters), as `config`
/// holds them or else their defaults, in MethodNames() order. Thread-safe.
std::vector<core::MethodParameters> MethodParametersOf(const core::DescriptorConfig& config);

/// A section of declared descriptor parameters (docs/options.md) and the methods it configures.
struct ParameterSection {
    std::string name;                   ///< YAML section
    std::vector<core::Method> methods;  ///< the methods that read it
    /// Visits copies of its parameters as the config held them (core::VisitCopies).
    std::function<void(core::ParameterVisitor&)> visit;
};

/// Every section of declared parameters, as `config` holds them, in dump-config's order:
/// histogram (height, range), ndt, then MethodParametersOf(config). Thread-safe.
std::vector<ParameterSection> ParameterSectionsOf(const core::DescriptorConfig& config);

/// The section of `sections` that `method` reads, or nullptr when it has none.
const ParameterSection* SectionOf(const std::vector<ParameterSection>& sections,
                                  const core::Method& method);

/// MethodOf(config.method).Describe(cloud, config): ConfigError for an invalid config,
/// EmptyInputError for a scan with nothing usable. Thread-safe.
core::Descriptor ComputeDescriptor(const core::PointCloud& cloud,
                                   const core::DescriptorConfig& config);

/// ComputeDescriptor for points owned elsewhere: MethodOf(config.method).DescribeView, which
/// copies them only for methods that cannot read a view. Thread-safe.
core::Descriptor ComputeDescriptorView(core::PointsView points,
                                       const core::DescriptorConfig& config);

/// The distance between two descriptors of the same method (ConfigError on mixed methods).
double DescriptorDistance(const core::Descriptor& a, const core::Descriptor& b);

/// The method's default decision threshold.
double DefaultThreshold(const core::Method& method);

/// Whether `distance` says "same place" under `threshold`, with the method's own comparison:
/// W <= tau (Röhling eq. 7), sigma' < t_d (Magnusson II-E, table I).
bool IsMatch(const core::Method& method, double distance, double threshold);

}  // namespace lidarloop::pipeline

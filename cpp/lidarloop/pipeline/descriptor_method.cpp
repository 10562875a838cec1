#include "lidarloop/pipeline/descriptor_method.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/pipeline/histogram_method.hpp"
#include "lidarloop/pipeline/ndt_method.hpp"
#include "lidarloop/pipeline/scancontext_method.hpp"

namespace lidarloop::pipeline {
namespace {

// Every registered method in registration order. Methods are never removed, so a reference to
// one stays valid for the life of the process.
class Registry {
public:
    Registry() {
        // The built-in methods: one line each.
        Add(std::make_shared<HistogramMethod>(core::Method::kHeight));
        Add(std::make_shared<HistogramMethod>(core::Method::kRange));
        Add(std::make_shared<NdtMethod>());
        Add(std::make_shared<ScanContextMethod>());
    }

    void Add(std::shared_ptr<const DescriptorMethod> method) {
        if (!method) throw core::ConfigError("RegisterMethod: no method given");
        const std::lock_guard<std::mutex> lock(mutex_);
        for (const auto& known : methods_) {
            if (known->method() == method->method()) {
                throw core::ConfigError("a descriptor method named '" + method->name() +
                                        "' is already registered");
            }
        }
        methods_.push_back(std::move(method));
    }
    const DescriptorMethod* Find(const core::Method& method) const {
        const std::lock_guard<std::mutex> lock(mutex_);
        for (const auto& known : methods_) {
            if (known->method() == method) return known.get();
        }
        return nullptr;
    }
    std::vector<std::string> Names() const {
        const std::lock_guard<std::mutex> lock(mutex_);
        std::vector<std::string> names;
        for (const auto& known : methods_) names.push_back(known->name());
        return names;
    }

private:
    mutable std::mutex mutex_;
    std::vector<std::shared_ptr<const DescriptorMethod>> methods_;
};

Registry& TheRegistry() {
    static Registry registry;
    return registry;
}

[[noreturn]] void FailUnknown(std::string_view name) {
    throw core::ConfigError("unknown method " + core::Quoted(name) +
                            " (valid: " + MethodNamesText(", ") + ")");
}

}  // namespace

core::Descriptor DescriptorMethod::DescribeView(core::PointsView points,
                                                const core::DescriptorConfig& config) const {
    // One buffer per thread, kept between calls: a fresh 1.4 MB copy of a 120k-point scan is
    // mapped anew by malloc each time, and its page faults cost ~0.5 ms (docs/BENCHMARK.md,
    // "Python bindings"). Describe does not keep a reference to its input.
    thread_local core::PointCloud copy;
    copy.assign(points.begin(), points.end());
    return Describe(copy, config);
}

void DescriptorMethod::ValidateThreshold(double threshold) const {
    if (!(std::isfinite(threshold) && threshold >= 0.0)) {
        throw core::ConfigError("detection.threshold must be a finite number >= 0, got " +
                                core::NumberText(threshold));
    }
}

void RegisterMethod(std::shared_ptr<const DescriptorMethod> method) {
    TheRegistry().Add(std::move(method));
}

const DescriptorMethod& MethodOf(const core::Method& method) {
    const DescriptorMethod* found = TheRegistry().Find(method);
    if (found == nullptr) FailUnknown(method.name());
    return *found;
}

core::Method ParseMethod(std::string_view name) {
    if (name.empty() || name.size() > core::Method::kMaxName) FailUnknown(name);
    const core::Method method(name);
    if (TheRegistry().Find(method) == nullptr) FailUnknown(name);
    return method;
}

std::vector<std::string> MethodNames() { return TheRegistry().Names(); }

std::string MethodNamesText(std::string_view separator) {
    std::string text;
    for (const std::string& name : MethodNames()) {
        if (!text.empty()) text += separator;
        text += name;
    }
    return text;
}

std::vector<core::MethodParameters> MethodParametersOf(const core::DescriptorConfig& config) {
    std::vector<core::MethodParameters> all;
    for (const std::string& name : MethodNames()) {
        std::optional<core::MethodParameters> defaults =
            MethodOf(ParseMethod(name)).DefaultParameters();
        if (!defaults) continue;
        const core::MethodParameters* held = config.methods.Find(defaults->section());
        all.push_back(held != nullptr ? *held : std::move(*defaults));
    }
    return all;
}

std::vector<ParameterSection> ParameterSectionsOf(const core::DescriptorConfig& config) {
    using core::HistogramConfig;
    using core::NdtConfig;
    std::vector<ParameterSection> sections;
    sections.push_back(
        {HistogramConfig::kSection,
         {core::Method::kHeight, core::Method::kRange},
         [c = config.histogram](core::ParameterVisitor& v) { core::VisitCopies(c, v); }});
    sections.push_back({NdtConfig::kSection,
                        {core::Method::kNdt},
                        [c = config.ndt](core::ParameterVisitor& v) { core::VisitCopies(c, v); }});
    for (core::MethodParameters& p : MethodParametersOf(config)) {
        const core::Method method = ParseMethod(p.section());
        sections.push_back({p.section(), {method}, [p](core::ParameterVisitor& v) {
                                core::MethodParameters copy = p;
                                copy.Visit(v);
                            }});
    }
    return sections;
}

const ParameterSection* SectionOf(const std::vector<ParameterSection>& sections,
                                  const core::Method& method) {
    for (const ParameterSection& section : sections) {
        if (std::find(section.methods.begin(), section.methods.end(), method) !=
            section.methods.end()) {
            return &section;
        }
    }
    return nullptr;
}

core::Descriptor ComputeDescriptor(const core::PointCloud& cloud,
                                   const core::DescriptorConfig& config) {
    return MethodOf(config.method).Describe(cloud, config);
}

core::Descriptor ComputeDescriptorView(core::PointsView points,
                                       const core::DescriptorConfig& config) {
    return MethodOf(config.method).DescribeView(points, config);
}

double DescriptorDistance(const core::Descriptor& a, const core::Descriptor& b) {
    if (!(a.method == b.method)) {
        throw core::ConfigError("cannot compare a " + core::ToString(a.method) +
                                " descriptor with a " + core::ToString(b.method) + " descriptor");
    }
    return MethodOf(a.method).Distance(a, b);
}

double DefaultThreshold(const core::Method& method) { return MethodOf(method).DefaultThreshold(); }

bool IsMatch(const core::Method& method, double distance, double threshold) {
    return MethodOf(method).IsMatch(distance, threshold);
}

}  // namespace lidarloop::pipeline

#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/histogram.hpp"
#include "lidarloop/core/ndt/ndt_config.hpp"
#include "lidarloop/core/parameters.hpp"

namespace lidarloop::core {

/// A place descriptor method, named as it is registered (pipeline/descriptor_method.hpp says
/// how a method describes and compares scans; pipeline::ParseMethod checks a name). A value
/// type: the name (at most kMaxName characters) is stored inline, so the built-in constants are
/// constant-initialised.
class Method {
public:
    static constexpr std::size_t kMaxName = 31;
    static const Method kHeight;  ///< Röhling 2015 histogram of heights above the ground plane
    static const Method kRange;   ///< Röhling 2015 histogram of ranges
    static const Method kNdt;     ///< Magnusson 2009 NDT appearance descriptor

    constexpr Method() = default;
    /// ConfigError when `name` is empty or longer than kMaxName.
    constexpr explicit Method(std::string_view name) {
        if (name.empty() || name.size() > kMaxName) {
            throw ConfigError("a method name has 1 to 31 characters, got " + Quoted(name));
        }
        std::copy(name.begin(), name.end(), name_.begin());
        size_ = name.size();
    }
    std::string_view name() const { return {name_.data(), size_}; }
    bool operator==(const Method& other) const { return name() == other.name(); }

private:
    std::array<char, kMaxName> name_{};
    std::size_t size_ = 0;
};

inline constexpr Method Method::kHeight{"height"};
inline constexpr Method Method::kRange{"range"};
inline constexpr Method Method::kNdt{"ndt"};

inline std::string ToString(const Method& method) { return std::string(method.name()); }

/// True for the methods built on Röhling's histograms (height, range).
bool IsHistogramMethod(const Method& method);

/// The projection a histogram method uses; throws ConfigError for any other method.
Projection ProjectionOf(const Method& method);

/// The parameters of the registered methods that declare any
/// (pipeline::DescriptorMethod::DefaultParameters), by section, which is the method's name. A
/// section not held has its defaults; equality treats the two alike. A value type.
class MethodSections {
public:
    /// The parameters held for `section`, or nullptr (then they are the method's defaults).
    const MethodParameters* Find(std::string_view section) const;
    MethodParameters* Find(std::string_view section);
    /// Holds `parameters` under their section, replacing what was held there.
    void Set(MethodParameters parameters);
    /// The held parameters, in the order first set.
    const std::vector<MethodParameters>& held() const { return held_; }

    /// The config struct of `section`: the one held, else Config{} (the defaults). ConfigError
    /// when the section holds another type (another method's parameters under this name).
    template <typename Config>
    const Config& Get(std::string_view section) const {
        static const Config kDefaults{};
        const MethodParameters* held = Find(section);
        if (held == nullptr) return kDefaults;
        if (const Config* config = held->As<Config>()) return *config;
        throw ConfigError("the parameters of section '" + std::string(section) +
                          "' are of another method");
    }
    /// The config struct of `section` to change; holds its defaults first when none are held.
    template <typename Config>
    Config& Mutable(std::string_view section) {
        if (Find(section) == nullptr) Set(MethodParameters(std::string(section), Config{}));
        if (Config* config = Find(section)->As<Config>()) return *config;
        throw ConfigError("the parameters of section '" + std::string(section) +
                          "' are of another method");
    }

    /// Throws ConfigError naming the first invalid parameter of a held section.
    void Validate() const;
    bool operator==(const MethodSections& other) const;

private:
    std::vector<MethodParameters> held_;
};

/// Everything that decides how a scan becomes a descriptor, and nothing else: two equal configs
/// give comparable descriptors. The single home of the descriptor defaults.
struct DescriptorConfig {
    /// Range: its top-k candidates hold a true loop most often, which is what verification
    /// needs (docs/verification.md, "Evidence for the defaults").
    Method method = Method::kRange;
    HistogramConfig histogram;
    NdtConfig ndt;
    /// The parameters of the other registered methods (scancontext, ...), by their names.
    MethodSections methods;

    /// Throws ConfigError naming the first invalid field.
    void Validate() const {
        histogram.Validate();
        ndt.Validate();
        methods.Validate();
    }
    bool operator==(const DescriptorConfig&) const = default;
};

}  // namespace lidarloop::core

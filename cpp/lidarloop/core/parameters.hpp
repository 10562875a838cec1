#pragma once

// Parameters declared once (docs/options.md). A config struct lists its parameters in one static
// member template, Declare(self, visit), calling visit(self.member, ParameterInfo{...}) for each:
// the key, the help line, the unit and the valid range are written there and nowhere else, the
// type is the member's and the default its in-class initialiser. Validation, the YAML config,
// `dump-config`, the command-line flags, the Python keywords and the docs' tables are derived
// from it. MethodParameters carries such a struct type-erased, so that a registered method's
// parameters reach all of these without any of them naming its type.

#include <charconv>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {

/// One declared parameter, as users are told about it.
struct ParameterInfo {
    std::string_view key;   ///< YAML key in its section ("rings"); flags and keywords follow it
    std::string_view help;  ///< one line: the YAML comment, the flag's and the keyword's help
    std::string_view unit;  ///< "m", "deg", ...; empty for counts, ratios, names and switches
    double min = -std::numeric_limits<double>::infinity();  ///< valid range, inclusive unless open
    double max = std::numeric_limits<double>::infinity();
    bool open = false;  ///< the bounds themselves are invalid: (min, max)

    bool HasRange() const { return std::isfinite(min) || std::isfinite(max); }
};

namespace detail {

// A bound as T writes it: the shortest text that reads back (0.01, not 0.0100000000000000002).
template <typename T>
std::string BoundText(double bound) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), static_cast<T>(bound));
    return std::string(buffer, result.ptr);
}

}  // namespace detail

/// The declared range of a number parameter of type T: "[1, 200]", "(0, 1)" (open), ">= 0" or
/// "<= 5" (one bound); "" when it has none. `to` joins two bounds as help and tables show them:
/// RangeText<int>(info, " to ") is "1 to 200" (an open range adds ", exclusive").
template <typename T>
std::string RangeText(const ParameterInfo& info, std::string_view to = {}) {
    const bool has_min = std::isfinite(info.min);
    const bool has_max = std::isfinite(info.max);
    if (has_min && has_max) {
        const std::string low = detail::BoundText<T>(info.min);
        const std::string high = detail::BoundText<T>(info.max);
        if (!to.empty()) return low + std::string(to) + high + (info.open ? ", exclusive" : "");
        return (info.open ? "(" : "[") + low + ", " + high + (info.open ? ")" : "]");
    }
    if (has_min) return (info.open ? "> " : ">= ") + detail::BoundText<T>(info.min);
    if (has_max) return (info.open ? "< " : "<= ") + detail::BoundText<T>(info.max);
    return "";
}

/// The value types a parameter of a registered method may have (MethodParameters); the built-in
/// sections also use enums, which the io layer reads by name.
class ParameterVisitor {
public:
    virtual ~ParameterVisitor() = default;
    virtual void Visit(const ParameterInfo& info, bool& value) = 0;
    virtual void Visit(const ParameterInfo& info, int& value) = 0;
    virtual void Visit(const ParameterInfo& info, std::size_t& value) = 0;
    virtual void Visit(const ParameterInfo& info, double& value) = 0;
    virtual void Visit(const ParameterInfo& info, std::optional<double>& value) = 0;
    virtual void Visit(const ParameterInfo& info, std::vector<double>& value) = 0;
    virtual void Visit(const ParameterInfo& info, std::string& value) = 0;
};

/// ConfigError "<section>.<key> must be in [min, max], got <value>" (or "in (min, max)",
/// "must be >= min", ...: RangeText) unless `value` (a number) lies in the declared range; a NaN
/// fails. The bounds are printed as the value's type.
template <typename T>
void CheckDeclaredRange(std::string_view section, const ParameterInfo& info, const T& value) {
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
        if (!info.HasRange()) return;
        const auto v = static_cast<double>(value);
        const bool inside =
            info.open ? v > info.min && v < info.max : v >= info.min && v <= info.max;
        if (inside) return;
        const std::string range = RangeText<T>(info);
        std::ostringstream message;
        message << section << "." << info.key << " must be "
                << (range[0] == '[' || range[0] == '(' ? "in " : "") << range << ", got " << value;
        throw ConfigError(message.str());
    }
}

/// Checks every declared range of `config` (Config::Declare) in declaration order, naming the
/// first value outside its range.
template <typename Config>
void CheckDeclaredRanges(std::string_view section, const Config& config) {
    Config::Declare(config, [&](const auto& value, const ParameterInfo& info) {
        CheckDeclaredRange(section, info, value);
    });
}

/// Visits a copy of every parameter of `config` (Config::Declare) in declaration order, for
/// flags, keywords and tables: what `visitor` changes is not kept. An enum is visited as its
/// name (ToString, found by argument-dependent lookup), so sections with enums fit the visitor.
template <typename Config>
void VisitCopies(const Config& config, ParameterVisitor& visitor) {
    Config::Declare(config, [&](const auto& value, const ParameterInfo& info) {
        using T = std::decay_t<decltype(value)>;
        if constexpr (std::is_enum_v<T>) {
            std::string name = ToString(value);
            visitor.Visit(info, name);
        } else {
            T copy = value;
            visitor.Visit(info, copy);
        }
    });
}

/// The parameters of a registered method: a value of its config struct (a copyable aggregate
/// with a static Declare, a Validate() and ==), under the method's name as YAML section. A value
/// type (copies are deep).
class MethodParameters {
public:
    template <typename Config>
    MethodParameters(std::string section, Config config)
        : section_(std::move(section)), self_(std::make_unique<Model<Config>>(std::move(config))) {}
    MethodParameters(const MethodParameters& other)
        : section_(other.section_), self_(other.self_->Clone()) {}
    MethodParameters& operator=(const MethodParameters& other) {
        if (this != &other) *this = MethodParameters(other);
        return *this;
    }
    MethodParameters(MethodParameters&&) noexcept = default;
    MethodParameters& operator=(MethodParameters&&) noexcept = default;
    ~MethodParameters() = default;

    /// The YAML section: the method's name.
    const std::string& section() const { return section_; }
    /// Visits every parameter in declaration order, for reading or writing it.
    void Visit(ParameterVisitor& visitor) { self_->Visit(visitor); }
    /// Throws ConfigError naming the first invalid parameter.
    void Validate() const { self_->Validate(); }
    /// Whether every parameter has its default.
    bool IsDefault() const { return self_->IsDefault(); }
    bool operator==(const MethodParameters& other) const {
        return section_ == other.section_ && self_->Equals(*other.self_);
    }
    /// The config struct, or nullptr when it is of another type.
    template <typename Config>
    const Config* As() const {
        const auto* model = dynamic_cast<const Model<Config>*>(self_.get());
        return model != nullptr ? &model->value : nullptr;
    }
    template <typename Config>
    Config* As() {
        auto* model = dynamic_cast<Model<Config>*>(self_.get());
        return model != nullptr ? &model->value : nullptr;
    }

private:
    struct Concept {
        virtual ~Concept() = default;
        virtual std::unique_ptr<Concept> Clone() const = 0;
        virtual void Visit(ParameterVisitor& visitor) = 0;
        virtual void Validate() const = 0;
        virtual bool IsDefault() const = 0;
        virtual bool Equals(const Concept& other) const = 0;
    };
    template <typename Config>
    struct Model final : Concept {
        explicit Model(Config c) : value(std::move(c)) {}
        std::unique_ptr<Concept> Clone() const override { return std::make_unique<Model>(value); }
        void Visit(ParameterVisitor& visitor) override {
            Config::Declare(value, [&](auto& member, const ParameterInfo& info) {
                visitor.Visit(info, member);
            });
        }
        void Validate() const override { value.Validate(); }
        bool IsDefault() const override { return value == Config{}; }
        bool Equals(const Concept& other) const override {
            const auto* same = dynamic_cast<const Model*>(&other);
            return same != nullptr && same->value == value;
        }
        Config value;
    };

    std::string section_;
    std::unique_ptr<Concept> self_;
};

}  // namespace lidarloop::core

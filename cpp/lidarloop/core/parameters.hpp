#pragma once

// Parameters declared once (docs/options.md). A config struct lists its parameters in one static
// member template, Declare(self, visit), calling visit(self.member, ParameterInfo{...}) for each:
// the key, the help line, the unit and the valid range are written there and nowhere else, the
// type is the member's and the default its in-class initialiser. Validation, the YAML config,
// `dump-config`, the command-line flags, the Python keywords and the docs' tables are derived
// from it. MethodParameters carries such a struct type-erased, so that a registered method's
// parameters reach all of these without any of them naming its type.

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
    double min = -std::numeric_limits<double>::infinity();  ///< valid range, inclusive (numbers)
    double max = std::numeric_limits<double>::infinity();

    bool HasRange() const { return std::isfinite(min) || std::isfinite(max); }
};

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

/// ConfigError "<section>.<key> must be in [min, max], got <value>" unless `value` (a number)
/// lies in the declared range; a NaN fails. The bounds are printed as the value's type.
template <typename T>
void CheckDeclaredRange(std::string_view section, const ParameterInfo& info, const T& value) {
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
        if (!info.HasRange()) return;
        const auto v = static_cast<double>(value);
        if (v >= info.min && v <= info.max) return;
        std::ostringstream message;
        message << section << "." << info.key << " must be in [";
        if constexpr (std::is_integral_v<T>) {
            message << static_cast<long long>(info.min) << ", " << static_cast<long long>(info.max);
        } else {
            message << info.min << ", " << info.max;
        }
        message << "], got " << value;
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

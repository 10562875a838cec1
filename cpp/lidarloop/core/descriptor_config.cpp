#include "lidarloop/core/descriptor_config.hpp"

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {

bool IsHistogramMethod(const Method& method) {
    return method == Method::kHeight || method == Method::kRange;
}

Projection ProjectionOf(const Method& method) {
    if (method == Method::kHeight) return Projection::kHeight;
    if (method == Method::kRange) return Projection::kRange;
    throw ConfigError("method '" + ToString(method) + "' is not a histogram projection");
}

const MethodParameters* MethodSections::Find(std::string_view section) const {
    for (const MethodParameters& p : held_) {
        if (p.section() == section) return &p;
    }
    return nullptr;
}

MethodParameters* MethodSections::Find(std::string_view section) {
    for (MethodParameters& p : held_) {
        if (p.section() == section) return &p;
    }
    return nullptr;
}

void MethodSections::Set(MethodParameters parameters) {
    if (MethodParameters* held = Find(parameters.section())) {
        *held = std::move(parameters);
    } else {
        held_.push_back(std::move(parameters));
    }
}

void MethodSections::Validate() const {
    for (const MethodParameters& p : held_) p.Validate();
}

// A section held by one side only is equal when it holds the defaults.
bool MethodSections::operator==(const MethodSections& other) const {
    const auto covered = [](const MethodSections& a, const MethodSections& b) {
        for (const MethodParameters& p : a.held_) {
            const MethodParameters* q = b.Find(p.section());
            if (q != nullptr ? !(p == *q) : !p.IsDefault()) return false;
        }
        return true;
    };
    return covered(*this, other) && covered(other, *this);
}

}  // namespace lidarloop::core

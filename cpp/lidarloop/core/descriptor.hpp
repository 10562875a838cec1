#pragma once

#include <cxxabi.h>

#include <any>
#include <cstdlib>
#include <memory>
#include <string>
#include <typeinfo>

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/histogram.hpp"
#include "lidarloop/core/ndt/ndt_descriptor.hpp"

namespace lidarloop::core {

/// The place descriptor of one scan under any method: what detection, evaluation and benchmarks
/// handle without knowing which paper it comes from. `value` holds the method's own type:
/// Histogram for height and range, NdtDescriptorSet for ndt, whatever a registered method
/// chooses (pipeline/descriptor_method.hpp computes and compares them).
/// The C++ name of `type` as written in the source ("lidarloop::core::ScanContext"), for messages.
inline std::string ReadableTypeName(const std::type_info& type) {
    int status = 0;
    const std::unique_ptr<char, decltype(&std::free)> name(
        abi::__cxa_demangle(type.name(), nullptr, nullptr, &status), &std::free);
    return status == 0 && name ? std::string(name.get()) : std::string(type.name());
}

struct Descriptor {
    Method method = Method::kHeight;
    std::any value;

    /// The value as the method's type T; ConfigError when it holds another type.
    template <typename T>
    const T& As() const {
        const T* typed = std::any_cast<T>(&value);
        if (typed == nullptr) {
            throw ConfigError("the " + ToString(method) + " descriptor does not hold a " +
                              ReadableTypeName(typeid(T)) + " (another method's descriptor)");
        }
        return *typed;
    }
    const Histogram& histogram() const { return As<Histogram>(); }
    const NdtDescriptorSet& ndt() const { return As<NdtDescriptorSet>(); }
};

}  // namespace lidarloop::core

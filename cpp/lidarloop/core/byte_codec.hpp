#pragma once

// Little-endian encoding of lidarloop's own binary data (similarity matrices, descriptor
// databases) in memory; the io layer puts it into files. Header-only.

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {

/// `a * b`, or nullopt when the product does not fit in a size_t.
inline std::optional<std::size_t> CheckedMul(std::size_t a, std::size_t b) {
    if (a != 0 && b > std::numeric_limits<std::size_t>::max() / a) return std::nullopt;
    return a * b;
}

/// The value of type T stored at `bytes` (any alignment) in byte order `order`. Correct on any
/// host byte order, free of aliasing UB, and a single load where `order` is the host's.
template <typename T>
T Load(const char* bytes, std::endian order) {
    std::array<char, sizeof(T)> buffer;
    std::memcpy(buffer.data(), bytes, sizeof(T));
    if (order != std::endian::native) std::reverse(buffer.begin(), buffer.end());
    return std::bit_cast<T>(buffer);
}

/// Stores `value` at `bytes` (any alignment) in byte order `order`; the inverse of Load.
template <typename T>
void Store(T value, char* bytes, std::endian order) {
    auto buffer = std::bit_cast<std::array<char, sizeof(T)>>(value);
    if (order != std::endian::native) std::reverse(buffer.begin(), buffer.end());
    std::memcpy(bytes, buffer.data(), sizeof(T));
}

template <typename T>
T LoadLittle(const char* bytes) {
    return Load<T>(bytes, std::endian::little);
}

template <typename T>
void StoreLittle(T value, char* bytes) {
    Store(value, bytes, std::endian::little);
}

/// Appends scalars and arrays to a byte buffer in little-endian order.
class ByteWriter {
public:
    template <typename T>
    void Put(T value) {
        static_assert(std::is_arithmetic_v<T>);
        char bytes[sizeof(T)];
        StoreLittle(value, bytes);
        data_.append(bytes, sizeof(T));
    }
    template <typename T>
    void PutArray(const T* values, std::size_t count) {
        for (std::size_t i = 0; i < count; ++i) Put(values[i]);
    }
    void PutString(const std::string& text) {
        Put<std::uint64_t>(text.size());
        data_.append(text);
    }
    void PutMagic(const char* magic) { data_.append(magic); }
    const std::string& data() const { return data_; }
    /// Empties the buffer and keeps its capacity, for writing a file piece by piece.
    void Clear() { data_.clear(); }

private:
    std::string data_;
};

/// Reads what ByteWriter wrote. Every read is bounds-checked; a short or damaged buffer calls
/// `fail` with a message that says what was being read (`fail` must throw; by default it throws
/// FormatError).
class ByteReader {
public:
    using Failure = std::function<void(const std::string& problem)>;

    explicit ByteReader(std::string data, Failure fail = {})
        : data_(std::move(data)), fail_(std::move(fail)) {}

    template <typename T>
    T Get(const char* what) {
        Require(sizeof(T), what);
        const T value = LoadLittle<T>(data_.data() + offset_);
        offset_ += sizeof(T);
        return value;
    }
    template <typename T>
    void GetArray(T* values, std::size_t count, const char* what) {
        const auto bytes = CheckedMul(count, sizeof(T));
        if (!bytes) Fail(std::string("absurd size of ") + what);
        Require(*bytes, what);
        for (std::size_t i = 0; i < count; ++i) values[i] = Get<T>(what);
    }
    std::string GetString(const char* what) {
        const auto size = Get<std::uint64_t>(what);
        Require(size, what);
        std::string text = data_.substr(offset_, size);
        offset_ += size;
        return text;
    }
    bool StartsWith(const std::string& prefix) const {
        return data_.compare(0, prefix.size(), prefix) == 0;
    }
    void ExpectMagic(const std::string& magic, const char* format) {
        if (data_.compare(0, magic.size(), magic) != 0) {
            Fail(std::string("not a ") + format + " file (wrong magic)");
        }
        offset_ = magic.size();
    }
    /// Fails unless the next `count` items of `item_bytes` each fit in what is left (checked
    /// before allocating for them).
    void RequireItems(std::uint64_t count, std::size_t item_bytes, const char* what) {
        const auto bytes = CheckedMul(count, item_bytes);
        if (!bytes) Fail(std::string("absurd count of ") + what);
        Require(*bytes, what);
    }
    bool AtEnd() const { return offset_ == data_.size(); }
    [[noreturn]] void Fail(const std::string& problem) const {
        if (fail_) fail_(problem);
        throw FormatError(problem);
    }

private:
    void Require(std::size_t bytes, const char* what) const {
        if (data_.size() - offset_ < bytes) {
            Fail(std::string("truncated: ") + what + " needs " + std::to_string(bytes) +
                 " bytes at offset " + std::to_string(offset_) + ", " +
                 std::to_string(data_.size() - offset_) + " left");
        }
    }

    std::string data_;
    Failure fail_;
    std::size_t offset_ = 0;
};

}  // namespace lidarloop::core

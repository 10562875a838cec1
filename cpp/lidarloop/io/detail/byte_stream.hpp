#pragma once

// Little-endian serialisation of lidarloop's own binary files (similarity matrix, database).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <type_traits>
#include <vector>

#include "lidarloop/io/detail/binary_io.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io::detail {

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

private:
    std::string data_;
};

/// Reads what ByteWriter wrote; every read is bounds-checked and a short file is a ReadError
/// that says what was being read.
class ByteReader {
public:
    ByteReader(const std::filesystem::path& file, std::string data)
        : file_(file), data_(std::move(data)) {}

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
    [[noreturn]] void Fail(const std::string& problem) const { throw ReadError(file_, problem); }

private:
    void Require(std::size_t bytes, const char* what) const {
        if (data_.size() - offset_ < bytes) {
            Fail(std::string("truncated: ") + what + " needs " + std::to_string(bytes) +
                 " bytes at offset " + std::to_string(offset_) + ", " +
                 std::to_string(data_.size() - offset_) + " left");
        }
    }

    std::filesystem::path file_;
    std::string data_;
    std::size_t offset_ = 0;
};

}  // namespace lidarloop::io::detail

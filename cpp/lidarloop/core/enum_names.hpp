#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {

/// One row of an enum's name table: the value and the name it has in configs, flags and files.
template <typename Enum>
struct EnumName {
    Enum value;
    std::string_view name;
};

/// A name table: one row per enumerator, in the order the valid names are listed in messages.
/// Written once per enum, e.g.
///   constexpr auto kProjectionNames = std::to_array<EnumName<Projection>>(
///       {{Projection::kHeight, "height"}, {Projection::kRange, "range"}});
///   static_assert(IsOneToOne(kProjectionNames));
/// and both directions (NameOf, ParseEnum) derive from it, so a name cannot be added to one and
/// forgotten in the other.
template <typename Enum, std::size_t N>
using EnumNames = std::array<EnumName<Enum>, N>;

/// True when no value and no name appears twice, so that NameOf and FindEnum are inverse; check
/// each table with static_assert(IsOneToOne(kTable)).
template <typename Enum, std::size_t N>
constexpr bool IsOneToOne(const EnumNames<Enum, N>& table) {
    for (std::size_t i = 0; i < N; ++i) {
        for (std::size_t j = i + 1; j < N; ++j) {
            if (table[i].value == table[j].value || table[i].name == table[j].name) return false;
        }
    }
    return true;
}

/// The name of `value`; `fallback` only for a value outside the table (an integer cast to the
/// enum). The view points into the table's string literals, valid for the program's lifetime.
template <typename Enum, std::size_t N>
constexpr std::string_view NameOf(const EnumNames<Enum, N>& table, Enum value,
                                  std::string_view fallback = "unknown") {
    for (const EnumName<Enum>& row : table) {
        if (row.value == value) return row.name;
    }
    return fallback;
}

/// The value named `name` (exact, case-sensitive match), or nullopt.
template <typename Enum, std::size_t N>
constexpr std::optional<Enum> FindEnum(const EnumNames<Enum, N>& table, std::string_view name) {
    for (const EnumName<Enum>& row : table) {
        if (row.name == name) return row.value;
    }
    return std::nullopt;
}

/// The names in table order joined by ", ", the last two by `last_separator`: "a, b, c" or, with
/// " or ", "a, b or c".
template <typename Enum, std::size_t N>
std::string JoinNames(const EnumNames<Enum, N>& table, std::string_view last_separator = ", ") {
    std::string joined;
    for (std::size_t i = 0; i < N; ++i) {
        if (i > 0) joined += i + 1 == N ? last_separator : std::string_view(", ");
        joined += table[i].name;
    }
    return joined;
}

/// The value named `name`; throws ConfigError "unknown <what> '<name>' (valid: a, b, c)".
template <typename Enum, std::size_t N>
Enum ParseEnum(const EnumNames<Enum, N>& table, std::string_view name, std::string_view what) {
    if (const std::optional<Enum> value = FindEnum(table, name)) return *value;
    throw ConfigError("unknown " + std::string(what) + " " + Quoted(name) +
                      " (valid: " + JoinNames(table) + ")");
}

}  // namespace lidarloop::core

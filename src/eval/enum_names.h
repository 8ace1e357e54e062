#pragma once
// Internal: the names of the evaluation enums kept in one table each, so that ToString and FromString
// (and any other per-value text) are lookups instead of hand-written switches that must agree.

#include <array>
#include <optional>
#include <string_view>
#include <utility>

namespace cheval::eval::detail {

/// One row per enum value: the value and its texts (name first, then e.g. a title or a unit).
template <typename Enum, size_t Values, size_t Texts = 1>
using NameTable = std::array<std::pair<Enum, std::array<std::string_view, Texts>>, Values>;

/// Text `column` of `value` ("" if the value is not in the table).
template <typename Enum, size_t Values, size_t Texts>
std::string_view TextOf(const NameTable<Enum, Values, Texts>& table, Enum value, size_t column = 0) {
  for (const auto& [v, texts] : table) {
    if (v == value) return texts[column];
  }
  return "";
}

/// The value whose name (text 0) is `name`; nullopt if none.
template <typename Enum, size_t Values, size_t Texts>
std::optional<Enum> ValueOf(const NameTable<Enum, Values, Texts>& table, std::string_view name) {
  for (const auto& [v, texts] : table) {
    if (texts[0] == name) return v;
  }
  return std::nullopt;
}

}  // namespace cheval::eval::detail

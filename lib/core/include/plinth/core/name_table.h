// One table per enum: its values' names, read both ways (name and parse), so a name is written
// once. Freestanding: constexpr, no heap.
//
//   inline constexpr NameTable<Phase, 3> kPhaseNames{{{
//       {Phase::kFullContact, "full_contact"}, {Phase::kSliding, "sliding"}, ...}}};
//   kPhaseNames.name(Phase::kSliding)          -> "sliding"
//   kPhaseNames.parse("sliding", phase)        -> true, phase = Phase::kSliding
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

namespace plinth {

template <class Enum>
struct NamedValue {
  Enum value;
  const char* name;
};

template <class Enum, std::size_t N>
struct NameTable {
  std::array<NamedValue<Enum>, N> entries;

  // The value's name; `fallback` for a value not in the table (a corrupted or foreign value).
  [[nodiscard]] constexpr const char* name(Enum value, const char* fallback = "invalid") const {
    for (const NamedValue<Enum>& e : entries) {
      if (e.value == value) return e.name;
    }
    return fallback;
  }

  // True, with `out` set, when `text` is one of the names; `out` is untouched otherwise.
  [[nodiscard]] constexpr bool parse(std::string_view text, Enum& out) const {
    for (const NamedValue<Enum>& e : entries) {
      if (text == e.name) {
        out = e.value;
        return true;
      }
    }
    return false;
  }

  [[nodiscard]] constexpr std::size_t size() const { return N; }
  [[nodiscard]] constexpr auto begin() const { return entries.begin(); }
  [[nodiscard]] constexpr auto end() const { return entries.end(); }
};

}  // namespace plinth
